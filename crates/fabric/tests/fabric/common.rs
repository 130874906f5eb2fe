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

/// SplitMix64: a tiny seeded generator for noise in tests (no crate for ten lines).
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Self {
        Self(seed)
    }

    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Standard normal (Box–Muller).
    pub fn normal(&mut self) -> f64 {
        let u1 = self.uniform().max(1e-300);
        let u2 = self.uniform();
        (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
    }
}
