//! Prints an `overrides` fuzz input (a file libFuzzer saved) as a
//! regression input: its base scene's TOML with one `#set key=value` line
//! per override, the form that fuzz/regressions/*.toml and the `scene`
//! target read.
//!
//! `cargo run --manifest-path fuzz/Cargo.toml --example render -- INPUT...`

use arbitrary::{Arbitrary, Unstructured};
use ballcage_fuzz::overrides::Input;

fn main() {
    for path in std::env::args().skip(1) {
        let bytes = std::fs::read(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
        // libfuzzer-sys decodes a typed input this way.
        let input = Input::arbitrary_take_rest(Unstructured::new(&bytes))
            .unwrap_or_else(|e| panic!("{path}: not an `overrides` input: {e}"));
        let (text, overrides) = input.render();
        for o in &overrides {
            println!("#set {o}");
        }
        print!("{text}");
    }
}
