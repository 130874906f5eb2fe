//! Shared helpers: fixture loading, a seeded random source.

use std::path::PathBuf;

use atelier_fabric::Fabric;

/// The repository root.
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Names of the fabric fixtures.
pub const FIXTURES: [&str; 6] = [
    "cotton_broad",
    "wool_tropical",
    "polyester_tropical",
    "polyester_faille",
    "denim",
    "silk",
];

/// Load `fixtures/fabrics/<name>.ron`.
pub fn fixture(name: &str) -> Fabric {
    let path = root().join("fixtures/fabrics").join(format!("{name}.ron"));
    Fabric::load(&path).unwrap_or_else(|e| panic!("fixture {name}: {e}"))
}

/// The workspace's seeded generator (SplitMix64).
pub use atelier_fabric::noise::Rng;
