//! cargo-fuzz target: the try-on's photograph and mask readers (and the segmentation) on
//! arbitrary bytes taken as a PNG file. docs/hostile.md.
#![no_main]

#[path = "../../crates/cli/tests/loaders/mod.rs"]
mod loaders;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    loaders::load_picture(data.to_vec());
});
