//! Probe (not a test): the turned strip of a fixture fabric through the PARTY solver, fitted by
//! the continuum model, with the run's knobs on the command line:
//! `cargo run --release -p atelier-fit --example turned_probe -- silk warp 16 [rate °/s] [damping] [load s] [rest speed m/s]`.
use atelier_fabric::Fabric;
use atelier_fit::strip::{TurnedRun, turned_strip};
use atelier_fit::turned::fit_turned;
use atelier_solver::kes::Direction as StripDirection;
use std::path::Path;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let name = &args[0];
    let weft = args[1] == "weft";
    let segments: usize = args[2].parse().expect("cells");
    let d = TurnedRun::default();
    let get = |i: usize, default: f64| args.get(i).map_or(default, |s| s.parse().expect("number"));
    let run = TurnedRun {
        segments,
        rate_deg_s: get(3, d.rate_deg_s),
        damping: get(4, d.damping),
        load_time: get(5, d.load_time),
        rest_speed: get(6, d.rest_speed),
        ..d
    };
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let f = Fabric::load(&root.join(format!("fixtures/fabrics/{name}.ron"))).expect("fabric");
    let (hidden, direction) = if weft {
        (f.bending.weft, StripDirection::Weft)
    } else {
        (f.bending.warp, StripDirection::Warp)
    };
    let w = f.weight_per_area();
    let length = 3.0 * (hidden.rigidity() / w).cbrt();
    let t = std::time::Instant::now();
    let profiles =
        turned_strip(&f, direction, length, &[0.0, 90.0, 180.0], &run).expect("turned strip");
    let fit = fit_turned(&profiles, length, w).expect("fit");
    println!(
        "{name} {} {segments} cells, rate {} °/s, damping {}, load {} s: B {:+.1} %, M0 {:+.1} %, RMS {:.3} mm ({:.1} s)",
        args[1],
        run.rate_deg_s,
        run.damping,
        run.load_time,
        100.0 * (fit.rigidity / hidden.rigidity() - 1.0),
        100.0 * (fit.residual_moment / hidden.residual_moment() - 1.0),
        fit.rms * 1e3,
        t.elapsed().as_secs_f64()
    );
}
