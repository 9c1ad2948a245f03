//! A base scene (a small paper drill pipe or an example scene) with
//! fuzzer-chosen `key=value` overrides on its real keys
//! (ballcage_fuzz::overrides), checked like the `scene` target.
#![no_main]

use ballcage_fuzz::overrides::Input;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|input: Input| {
    let (text, overrides) = input.render();
    ballcage_fuzz::check_text(text, &overrides);
});
