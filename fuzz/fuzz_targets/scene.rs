//! Raw bytes as a TOML scene document: load (parse, validate, expand,
//! assemble), round-trip, a few steps, finite tables (ballcage_fuzz::check_text).
//! Comment lines `#set key=value` are overrides applied to the document, so
//! the fuzzer reaches the override syntax too and every saved regression
//! input (fuzz/regressions/*.toml) replays through this target.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        ballcage_fuzz::check_text(text, &ballcage_fuzz::set_lines(text));
    }
});
