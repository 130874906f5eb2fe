//! A fabric from KES summary values, without a file: the cotton broad of
//! `fixtures/fabrics/cotton_broad.ron` (Matsudaira et al. 2015) written as a [`FabricSpec`] in
//! KES units, converted once to SI by [`Fabric::from_spec`], and a few points of its tensile,
//! bending and shear loops printed.
//!
//! `cargo run --release -p atelier-fabric --example kes_fabric`

#![allow(clippy::print_stdout)] // an example shows its results on stdout

use atelier_fabric::spec::{BendingSpec, BendingSpecs, KesBending, KesTensile, Provenance};
use atelier_fabric::spec::{ShearSpec, TensileSpec, TensileSpecs};
use atelier_fabric::{AnisotropyForm, Fabric, FabricClass, FabricSpec};

/// KES tensile summary values LT (–), EMT (%), RT (%); Fm is the standard 500 gf/cm.
fn kes_tensile(lt: f64, emt_percent: f64, rt_percent: f64) -> TensileSpec {
    let (wt_gf_cm_cm2, fm_gf_cm) = (None, None);
    TensileSpec::Kes(KesTensile {
        lt,
        emt_percent,
        rt_percent,
        wt_gf_cm_cm2,
        fm_gf_cm,
    })
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // Bending B 0.118 gf·cm²/cm and 2HB 0.124 gf·cm/cm, the same along warp and weft.
    let bending = BendingSpec::Kes(KesBending {
        b_gf_cm2_cm: 0.118,
        two_hb_gf_cm_cm: 0.124,
    });
    let spec = FabricSpec {
        name: "cotton broad from KES values".into(),
        provenance: Provenance {
            source: "Matsudaira et al. (2015), as in fixtures/fabrics/cotton_broad.ron".into(),
            measured: vec![],
            banded: vec![],
            derived: vec![],
            notes: String::new(),
        },
        class: Some(FabricClass::CottonBroadcloth), // for the plausibility bands
        mass_per_area_mg_cm2: 12.38,
        thickness_mm: 0.497,
        friction: 0.6,
        // Warp and weft loops are synthesised from the summaries; the 45° bias loop is derived
        // from the shear values (G 1.5 gf/(cm·deg), 2HG 2.5 and 2HG5 4.5 gf/cm).
        tensile: TensileSpecs {
            warp: kes_tensile(0.72, 3.0, 48.0),
            weft: kes_tensile(0.68, 6.0, 45.0),
            bias45: None,
            bias135: None,
        },
        shear: Some(ShearSpec::kes(1.5, 2.5, Some(4.5))),
        bending: BendingSpecs {
            warp: bending.clone(),
            weft: bending,
            bias45: None,
            bias135: None,
        },
    };
    let fabric = Fabric::from_spec(&spec)?; // SI from here on: N, m, kg, rad

    let bend = fabric.bending.warp;
    let (b, m0) = (bend.rigidity() * 1e6, bend.residual_moment() * 1e6);
    let c = fabric.bending_length(0.0, AnisotropyForm::Thesis)? * 100.0;
    let mass = fabric.mass_per_area;
    println!("{}: mass per area {mass:.4} kg/m²", fabric.name);
    println!("  bending rigidity B {b:.3} µN·m, residual moment M₀ {m0:.1} µN·m/m");
    println!("  bending length (B/w)^(1/3) {c:.2} cm");

    // Tensile loop along the warp: strain on the loading and unloading branches at a few forces.
    let t = &fabric.tensile.warp;
    println!("tensile loop, warp (apex {:.0} N/m):", t.max_force());
    for force in [10.0, 50.0, 200.0, 490.0] {
        let (up, down) = t.strains(force);
        let (up, down) = (up * 100.0, down * 100.0);
        println!("  {force:>5.0} N/m: strain {up:.3} % loading, {down:.3} % unloading");
    }
    // Bending spindle: moment per width on the rising (Bη + M₀) and falling (Bη − M₀) branches.
    println!("bending loop, warp:");
    for k_per_cm in [0.5, 1.0, 2.5] {
        let k = k_per_cm * 100.0; // curvature, m⁻¹
        let (up, down) = (bend.rising_branch(k) * 1e6, bend.falling_branch(k) * 1e6);
        println!("  {k_per_cm:>4} cm⁻¹: moment {up:.0} µN·m/m rising, {down:.0} falling");
    }
    // In-plane shear (the KES-FB1 loop): force per width on the upper and lower branches.
    let shear = fabric.shear_loop()?;
    println!("shear loop (G {:.1} N/(m·rad)):", shear.stiffness());
    for deg in [1.0_f64, 3.0, 5.0] {
        let (up, down) = (shear.upper(deg.to_radians()), shear.lower(deg.to_radians()));
        println!("  {deg:>4}°: force {up:.2} N/m rising, {down:.2} N/m falling");
    }
    println!("plausibility warnings: {}", fabric.plausibility().len());
    Ok(())
}
