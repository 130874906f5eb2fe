//! Plausibility bands by fabric class (`reference/fabric-data.md` §4) and the check that warns
//! when a fabric leaves them. The bands are typical ranges from the textile literature, not
//! limits: a warning asks the user to double-check a value (a unit slip, a swapped column), it
//! does not reject the fabric.

use std::fmt;

use serde::{Deserialize, Serialize};

use crate::Fabric;
use crate::units;

/// A fabric class with typical KES bands.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum FabricClass {
    /// Silk (habutae, crêpe de chine).
    Silk,
    /// Polyester filament (taffeta, satin, faille).
    PolyesterFilament,
    /// Cotton broadcloth, poplin.
    CottonBroadcloth,
    /// Wool suiting (tropical, gabardine).
    WoolSuiting,
    /// Denim, canvas.
    DenimCanvas,
}

impl FabricClass {
    /// All classes, lightest first.
    pub const ALL: [FabricClass; 5] = [
        FabricClass::Silk,
        FabricClass::PolyesterFilament,
        FabricClass::CottonBroadcloth,
        FabricClass::WoolSuiting,
        FabricClass::DenimCanvas,
    ];

    /// The class's bands, in KES units.
    pub fn bands(self) -> Bands {
        let b = |lo, hi| (lo, hi);
        match self {
            FabricClass::Silk => Bands {
                w: b(3.0, 9.0),
                t: b(0.1, 0.35),
                emt: b(3.0, 15.0),
                lt: b(0.5, 0.8),
                b: b(0.005, 0.05),
                two_hb: b(0.002, 0.03),
                g: b(0.1, 0.7),
                two_hg5: b(0.1, 1.5),
            },
            FabricClass::PolyesterFilament => Bands {
                w: b(5.0, 12.0),
                t: b(0.1, 0.4),
                emt: b(2.0, 10.0),
                lt: b(0.6, 0.9),
                b: b(0.01, 0.15),
                two_hb: b(0.005, 0.05),
                g: b(0.3, 1.5),
                two_hg5: b(0.2, 2.0),
            },
            FabricClass::CottonBroadcloth => Bands {
                w: b(9.0, 14.0),
                t: b(0.25, 0.5),
                emt: b(2.0, 8.0),
                lt: b(0.6, 0.9),
                b: b(0.05, 0.2),
                two_hb: b(0.05, 0.2),
                g: b(0.8, 3.0),
                two_hg5: b(1.5, 8.0),
            },
            FabricClass::WoolSuiting => Bands {
                w: b(15.0, 30.0),
                t: b(0.4, 1.0),
                emt: b(3.0, 12.0),
                lt: b(0.5, 0.75),
                b: b(0.05, 0.2),
                two_hb: b(0.02, 0.1),
                g: b(0.4, 1.5),
                two_hg5: b(0.8, 3.0),
            },
            FabricClass::DenimCanvas => Bands {
                w: b(30.0, 45.0),
                t: b(0.6, 1.2),
                emt: b(1.0, 6.0),
                lt: b(0.7, 0.9),
                b: b(0.3, 2.0),
                two_hb: b(0.2, 1.0),
                g: b(2.0, 6.0),
                two_hg5: b(4.0, 12.0),
            },
        }
    }

    /// The union of all classes' bands (used when a fabric names no class).
    pub fn envelope() -> Bands {
        let mut e = FabricClass::Silk.bands();
        for c in FabricClass::ALL {
            let b = c.bands();
            for (x, y) in e.fields_mut().into_iter().zip(b.fields()) {
                x.0 = x.0.min(y.0);
                x.1 = x.1.max(y.1);
            }
        }
        e
    }
}

/// Typical ranges `(low, high)` in KES units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bands {
    /// W, mg/cm².
    pub w: (f64, f64),
    /// T, mm.
    pub t: (f64, f64),
    /// EMT, %.
    pub emt: (f64, f64),
    /// LT.
    pub lt: (f64, f64),
    /// B, gf·cm²/cm.
    pub b: (f64, f64),
    /// 2HB, gf·cm/cm.
    pub two_hb: (f64, f64),
    /// G, gf/(cm·deg).
    pub g: (f64, f64),
    /// 2HG5, gf/cm.
    pub two_hg5: (f64, f64),
}

impl Bands {
    fn fields(&self) -> [(f64, f64); 8] {
        [
            self.w,
            self.t,
            self.emt,
            self.lt,
            self.b,
            self.two_hb,
            self.g,
            self.two_hg5,
        ]
    }
    fn fields_mut(&mut self) -> [&mut (f64, f64); 8] {
        [
            &mut self.w,
            &mut self.t,
            &mut self.emt,
            &mut self.lt,
            &mut self.b,
            &mut self.two_hb,
            &mut self.g,
            &mut self.two_hg5,
        ]
    }
}

/// A value outside its band.
#[derive(Clone, Debug, PartialEq)]
pub struct PlausibilityWarning {
    /// Which quantity (`"EMT warp"`, `"B weft"`, …).
    pub quantity: String,
    /// Its value in KES units.
    pub value: f64,
    /// The band it left.
    pub band: (f64, f64),
    /// The class whose band it is; `None` for the envelope of all classes.
    pub class: Option<FabricClass>,
}

impl fmt::Display for PlausibilityWarning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let whose = match self.class {
            Some(c) => format!("the {c:?} band"),
            None => "the range of all fabric classes".to_owned(),
        };
        write!(
            f,
            "{} = {:.4} lies outside {whose} {}–{}",
            self.quantity, self.value, self.band.0, self.band.1
        )
    }
}

/// Compare a fabric with the bands of its class (or of all classes) and list what lies outside.
pub fn check(fabric: &Fabric) -> Vec<PlausibilityWarning> {
    let bands = fabric
        .class
        .map_or_else(FabricClass::envelope, FabricClass::bands);
    let mut values = vec![
        (
            "W".to_owned(),
            units::mass_per_area_to_kes(fabric.mass_per_area),
            bands.w,
        ),
        (
            "T".to_owned(),
            units::thickness_to_kes(fabric.thickness),
            bands.t,
        ),
    ];
    for (dir, tensile, bending) in [
        ("warp", &fabric.tensile.warp, &fabric.bending.warp),
        ("weft", &fabric.tensile.weft, &fabric.bending.weft),
    ] {
        let s = tensile.summary();
        values.push((
            format!("EMT {dir}"),
            units::strain_to_percent(s.emt),
            bands.emt,
        ));
        values.push((format!("LT {dir}"), s.lt, bands.lt));
        values.push((
            format!("B {dir}"),
            units::rigidity_to_kes(bending.rigidity()),
            bands.b,
        ));
        let two_hb = units::moment_to_kes(2.0 * bending.residual_moment());
        values.push((format!("2HB {dir}"), two_hb, bands.two_hb));
    }
    if let Some(shear) = &fabric.shear {
        values.push((
            "G".to_owned(),
            units::shear_stiffness_to_kes(shear.stiffness),
            bands.g,
        ));
        if let Some(h5) = shear.hysteresis_5deg {
            values.push(("2HG5".to_owned(), units::force_to_kes(h5), bands.two_hg5));
        }
    }
    values
        .into_iter()
        // A relative slack of 1e-9 keeps round-off at a band's edge from warning.
        .filter(|&(_, v, (lo, hi))| v < lo * (1.0 - 1e-9) || v > hi * (1.0 + 1e-9))
        .map(|(quantity, value, band)| PlausibilityWarning {
            quantity,
            value,
            band,
            class: fabric.class,
        })
        .collect()
}
