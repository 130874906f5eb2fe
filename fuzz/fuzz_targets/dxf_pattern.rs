//! cargo-fuzz target: the DXF-AAMA pattern reader and gridder on arbitrary bytes (read as
//! UTF-8, lossily). docs/hostile.md.
#![no_main]

#[path = "../../crates/cli/tests/loaders/mod.rs"]
mod loaders;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data).into_owned();
    loaders::load_dxf_pattern(text);
});
