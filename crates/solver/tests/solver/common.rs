//! Shared helpers for the validation scenes.

#![allow(dead_code)]

use std::path::PathBuf;

use atelier_fabric::Fabric;

/// The repository root.
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Load `fixtures/fabrics/<name>.ron`.
pub fn fabric(name: &str) -> Fabric {
    let path = root().join("fixtures/fabrics").join(format!("{name}.ron"));
    Fabric::load(&path).unwrap_or_else(|e| panic!("fixture {name}: {e}"))
}
