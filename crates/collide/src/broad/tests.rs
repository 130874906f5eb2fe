//! Property tests of the broad phases against brute force and against exact geometry.

use super::*;
use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed};

/// SplitMix64: the scene generator (proptest draws the seed and the sizes).
struct Rng(u64);

impl Rng {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n as u64) as usize
    }
    fn v3(&mut self, r: f64) -> V3 {
        V3::new(self.range(-r, r), self.range(-r, r), self.range(-r, r))
    }
}

/// A moving triangle soup (three own vertices per triangle) with its margin.
#[derive(Clone, Debug)]
struct Scene {
    start: Vec<V3>,
    end: Vec<V3>,
    triangles: Vec<[u32; 3]>,
    margin: f64,
}

/// Random soup of `n` triangles: ordinary, huge, tiny, axis-aligned flat, collinear,
/// collapsed to a point, and with a far vertex; moving or static.
fn scene(rng: &mut Rng, n: usize) -> Scene {
    let mut start = Vec::new();
    let mut end = Vec::new();
    let mut triangles = Vec::new();
    for t in 0..n {
        let c = rng.v3(1.0);
        let size = match rng.below(10) {
            0 => 50.0,
            1 => 1e-6,
            _ => rng.range(0.01, 0.5),
        };
        let mut p = [c + rng.v3(size), c + rng.v3(size), c + rng.v3(size)];
        match rng.below(8) {
            0 => {
                let k = rng.below(3);
                p[1][k] = p[0][k];
                p[2][k] = p[0][k];
            }
            1 => p[2] = p[0] + (p[1] - p[0]) * rng.range(-1.0, 2.0),
            2 => p = [c, c, c],
            3 => p[rng.below(3)] = rng.v3(1.0) * 1e6,
            _ => {}
        }
        let d = match rng.below(3) {
            0 => V3::zeros(),
            1 => rng.v3(0.3),
            _ => rng.v3(0.02),
        };
        let wobble = rng.below(2) == 0;
        for q in p {
            start.push(q);
            end.push(q + d + if wobble { rng.v3(0.01) } else { V3::zeros() });
        }
        let b = 3 * t as u32;
        triangles.push([b, b + 1, b + 2]);
    }
    let margin = if rng.below(3) == 0 {
        0.0
    } else {
        rng.range(0.0, 0.05)
    };
    Scene {
        start,
        end,
        triangles,
        margin,
    }
}

/// A query segment with radius: random, zero-length, axis-aligned, long, or aimed at a point
/// of a triangle at some time of the step.
fn query(rng: &mut Rng, s: &Scene) -> (V3, V3, f64) {
    let radius = if rng.below(3) == 0 {
        0.0
    } else {
        rng.range(0.0, 0.2)
    };
    let a = if !s.triangles.is_empty() && rng.below(2) == 0 {
        let t = s.triangles[rng.below(s.triangles.len())];
        let tau = rng.unit();
        let (u, v) = (rng.unit(), rng.unit());
        let (u, v) = if u + v > 1.0 {
            (1.0 - u, 1.0 - v)
        } else {
            (u, v)
        };
        let at = |k: u32| s.start[k as usize] * (1.0 - tau) + s.end[k as usize] * tau;
        let p = at(t[0]) * (1.0 - u - v) + at(t[1]) * u + at(t[2]) * v;
        p + rng.v3(0.1)
    } else {
        rng.v3(1.5)
    };
    let d = match rng.below(5) {
        0 => V3::zeros(),
        1 => {
            let mut d = V3::zeros();
            d[rng.below(3)] = rng.range(-0.3, 0.3);
            d
        }
        2 => rng.v3(2.0),
        _ => rng.v3(0.05),
    };
    // Centre the segment on the aimed point sometimes, so it may cross the triangle.
    let a = if rng.below(2) == 0 { a - d * 0.5 } else { a };
    (a, a + d, radius)
}

/// Closest points of segments `p1 q1` and `p2 q2` (Ericson, Real-Time Collision Detection
/// §5.1.9), returned as their distance; handles degenerate segments.
fn segment_segment(p1: &V3, q1: &V3, p2: &V3, q2: &V3) -> f64 {
    let d1 = q1 - p1;
    let d2 = q2 - p2;
    let r = p1 - p2;
    let a = d1.dot(&d1);
    let e = d2.dot(&d2);
    let f = d2.dot(&r);
    let eps = 1e-300;
    let (s, t);
    if a <= eps && e <= eps {
        return r.norm();
    }
    if a <= eps {
        s = 0.0;
        t = (f / e).clamp(0.0, 1.0);
    } else {
        let c = d1.dot(&r);
        if e <= eps {
            t = 0.0;
            s = (-c / a).clamp(0.0, 1.0);
        } else {
            let b = d1.dot(&d2);
            let denom = a * e - b * b;
            let mut s0 = if denom > 0.0 {
                ((b * f - c * e) / denom).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let mut t0 = (b * s0 + f) / e;
            if t0 < 0.0 {
                t0 = 0.0;
                s0 = (-c / a).clamp(0.0, 1.0);
            } else if t0 > 1.0 {
                t0 = 1.0;
                s0 = ((b - c) / a).clamp(0.0, 1.0);
            }
            s = s0;
            t = t0;
        }
    }
    ((p1 + d1 * s) - (p2 + d2 * t)).norm()
}

/// Distance of point `p` to the plane triangle `abc` when its projection falls inside
/// (else `None`: an edge is closer); `None` for degenerate triangles.
fn point_face(p: &V3, a: &V3, b: &V3, c: &V3) -> Option<f64> {
    let n = (b - a).cross(&(c - a));
    let nn = n.norm_squared();
    if nn <= 1e-300 {
        return None;
    }
    let inside = [(a, b), (b, c), (c, a)]
        .iter()
        .all(|(x, y)| (*y - *x).cross(&(p - *x)).dot(&n) >= 0.0);
    inside.then(|| (p - a).dot(&n).abs() / nn.sqrt())
}

/// Whether segment `p q` crosses the (non-degenerate) triangle `abc`.
fn segment_crosses(p: &V3, q: &V3, a: &V3, b: &V3, c: &V3) -> bool {
    let n = (b - a).cross(&(c - a));
    let dp = (p - a).dot(&n);
    let dq = (q - a).dot(&n);
    if n.norm_squared() <= 1e-300 || dp * dq > 0.0 || (dp == 0.0 && dq == 0.0) {
        return false;
    }
    let x = p + (q - p) * (dp / (dp - dq));
    point_face(&x, a, b, c).is_some()
}

/// Exact Euclidean distance between segment `p q` and triangle `abc` (possibly degenerate).
fn segment_triangle(p: &V3, q: &V3, a: &V3, b: &V3, c: &V3) -> f64 {
    if segment_crosses(p, q, a, b, c) {
        return 0.0;
    }
    let mut d = f64::INFINITY;
    for (x, y) in [(a, b), (b, c), (c, a)] {
        d = d.min(segment_segment(p, q, x, y));
    }
    for e in [p, q] {
        if let Some(f) = point_face(e, a, b, c) {
            d = d.min(f);
        }
    }
    d
}

/// Triangles that certainly meet the query: at one of a few sampled times of the step, the
/// segment comes within `radius + margin` of the triangle (with a hair of slack for rounding).
fn sampled_truth(s: &Scene, a: &V3, b: &V3, radius: f64) -> Vec<u32> {
    let reach = (radius + s.margin) * (1.0 - 1e-9) - 1e-12;
    let mut out = Vec::new();
    for (i, t) in s.triangles.iter().enumerate() {
        let hit = [0.0, 0.25, 0.5, 0.75, 1.0].iter().any(|&tau: &f64| {
            let at = |k: u32| s.start[k as usize] * (1.0 - tau) + s.end[k as usize] * tau;
            segment_triangle(a, b, &at(t[0]), &at(t[1]), &at(t[2])) <= reach
        });
        if hit {
            out.push(i as u32);
        }
    }
    out
}

fn run(bp: &dyn BroadPhase, a: &V3, b: &V3, r: f64) -> Vec<u32> {
    let mut out = vec![u32::MAX]; // appended to, not cleared
    bp.query(a, b, r, &mut out);
    assert_eq!(out.remove(0), u32::MAX);
    out
}

fn sorted_unique(mut v: Vec<u32>) -> Vec<u32> {
    let n = v.len();
    v.sort_unstable();
    v.dedup();
    assert_eq!(v.len(), n, "duplicate candidates");
    v
}

fn is_subset(small: &[u32], big: &[u32]) -> bool {
    small.iter().all(|x| big.binary_search(x).is_ok())
}

fn all_broads() -> Vec<(&'static str, Box<dyn BroadPhase>)> {
    vec![
        ("brute", new_broad(BroadKind::Brute)),
        ("bvh", new_broad(BroadKind::Bvh)),
        ("projection", new_broad(BroadKind::Projection)),
        (
            "projection-boxes",
            Box::new(ProjectionBroad::new().with_segment_test(false)),
        ),
    ]
}

fn config(cases: u32, seed: u64) -> Config {
    Config {
        cases,
        rng_seed: RngSeed::Fixed(seed),
        failure_persistence: None,
        ..Config::default()
    }
}

proptest! {
    #![proptest_config(config(1000, 0x00C0_111D))]

    /// BVH and box-only projection return exactly brute force; the projection with the segment
    /// test a subset of it; all a superset of the sampled exact truth; no duplicates.
    #[test]
    fn superset_of_truth(seed in any::<u64>(), n in 0usize..48) {
        let mut rng = Rng(seed);
        let s = scene(&mut rng, n);
        let mut broads = all_broads();
        for (_, bp) in &mut broads {
            bp.update(&s.start, &s.end, &s.triangles, s.margin);
        }
        for _ in 0..24 {
            let (a, b, r) = query(&mut rng, &s);
            let truth = sampled_truth(&s, &a, &b, r);
            let brute = sorted_unique(run(broads[0].1.as_ref(), &a, &b, r));
            prop_assert!(is_subset(&truth, &brute), "brute misses truth");
            for (name, bp) in &broads[1..] {
                let got = sorted_unique(run(bp.as_ref(), &a, &b, r));
                prop_assert!(is_subset(&truth, &got), "{name} misses {truth:?} ⊄ {got:?}");
                if *name == "projection" {
                    prop_assert!(is_subset(&got, &brute), "{name} beyond brute");
                } else {
                    prop_assert_eq!(&got, &brute, "{} differs from brute", name);
                }
            }
        }
    }

    /// A segment (radius 0) crossing a static triangle is always returned.
    #[test]
    fn crossing_segment_always_found(seed in any::<u64>(), n in 1usize..32) {
        let mut rng = Rng(seed);
        let mut s = scene(&mut rng, n);
        s.end.clone_from(&s.start);
        s.margin = 0.0;
        let mut broads = all_broads();
        for (_, bp) in &mut broads {
            bp.update(&s.start, &s.end, &s.triangles, 0.0);
        }
        for _ in 0..16 {
            let t = rng.below(n);
            let [i, j, k] = s.triangles[t].map(|x| s.start[x as usize]);
            let nrm = (j - i).cross(&(k - i));
            if nrm.norm() < 1e-14 {
                continue;
            }
            let (u, v) = (rng.unit(), rng.unit());
            let (u, v) = if u + v > 1.0 { (1.0 - u, 1.0 - v) } else { (u, v) };
            let x = i * (1.0 - u - v) + j * u + k * v;
            // Any direction not parallel to the plane, of any length.
            let mut d = rng.v3(1.0) * 10f64.powf(rng.range(-4.0, 1.0));
            if d.dot(&nrm).abs() < 1e-3 * d.norm() * nrm.norm() {
                d += nrm.normalize() * d.norm().max(1e-3);
            }
            let f = rng.unit();
            let (a, b) = (x - d * f, x + d * (1.0 - f));
            if !segment_crosses(&a, &b, &i, &j, &k) {
                continue; // rounding put x just outside
            }
            for (name, bp) in &broads {
                let got = run(bp.as_ref(), &a, &b, 0.0);
                prop_assert!(got.contains(&(t as u32)), "{name} misses crossed triangle {t}");
            }
        }
    }

    /// Results depend only on the last update: same answers after a history of other scenes
    /// (same and different triangle counts) as fresh; the BVH refits without rebuilding.
    #[test]
    fn independent_of_update_history(seed in any::<u64>(), n in 0usize..40, k in 1usize..8) {
        let mut rng = Rng(seed);
        let s = scene(&mut rng, n);
        let mut fresh = all_broads();
        let mut used = all_broads();
        let mut bvh = BvhBroad::new();
        for _ in 0..k {
            let m = if rng.below(3) == 0 { rng.below(40) } else { n };
            let other = scene(&mut rng, m);
            for (_, bp) in &mut used {
                bp.update(&other.start, &other.end, &other.triangles, other.margin);
            }
            // Same count every time: refits only.
            let same = scene(&mut rng, n);
            bvh.update(&same.start, &same.end, &same.triangles, same.margin);
        }
        bvh.update(&s.start, &s.end, &s.triangles, s.margin);
        prop_assert_eq!(bvh.builds(), 1);
        for ((_, f), (_, u)) in fresh.iter_mut().zip(&mut used) {
            f.update(&s.start, &s.end, &s.triangles, s.margin);
            u.update(&s.start, &s.end, &s.triangles, s.margin);
        }
        let mut fresh_bvh = BvhBroad::new();
        fresh_bvh.update(&s.start, &s.end, &s.triangles, s.margin);
        for _ in 0..16 {
            let (a, b, r) = query(&mut rng, &s);
            for ((name, f), (_, u)) in fresh.iter().zip(&used) {
                let x = sorted_unique(run(f.as_ref(), &a, &b, r));
                let y = sorted_unique(run(u.as_ref(), &a, &b, r));
                prop_assert_eq!(x, y, "{} depends on history", name);
            }
            let x = sorted_unique(run(&fresh_bvh, &a, &b, r));
            let y = sorted_unique(run(&bvh, &a, &b, r));
            prop_assert_eq!(x, y, "refitted BVH differs from fresh");
        }
    }
}

/// A BVH refitted through 200 steps of a deforming sheet answers like a fresh one.
#[test]
fn bvh_many_refits_match_fresh() {
    let (nx, ny) = (30, 30);
    let grid = |t: f64| -> Vec<V3> {
        let mut v = Vec::new();
        for j in 0..=ny {
            for i in 0..=nx {
                let (x, y) = (i as f64 / nx as f64, j as f64 / ny as f64);
                v.push(V3::new(
                    x,
                    y,
                    0.2 * (6.0 * x + t).sin() * (4.0 * y - t).cos(),
                ));
            }
        }
        v
    };
    let mut tris = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            let a = (j * (nx + 1) + i) as u32;
            let b = a + 1;
            let c = a + (nx + 1) as u32;
            tris.push([a, b, c + 1]);
            tris.push([a, c + 1, c]);
        }
    }
    let mut bvh = BvhBroad::new();
    let mut rng = Rng(7);
    for step in 0..200 {
        let t0 = step as f64 * 0.05;
        bvh.update(&grid(t0), &grid(t0 + 0.05), &tris, 0.001);
    }
    assert_eq!(bvh.builds(), 1);
    let (s, e) = (grid(199.0 * 0.05), grid(200.0 * 0.05));
    let mut fresh = BvhBroad::new();
    fresh.update(&s, &e, &tris, 0.001);
    let mut brute = BruteForce::new();
    brute.update(&s, &e, &tris, 0.001);
    let mut found = 0;
    for _ in 0..500 {
        let a = V3::new(rng.unit(), rng.unit(), rng.range(-0.3, 0.3));
        let b = a + rng.v3(0.02);
        let x = sorted_unique(run(&bvh, &a, &b, 0.01));
        let y = sorted_unique(run(&fresh, &a, &b, 0.01));
        let z = sorted_unique(run(&brute, &a, &b, 0.01));
        assert_eq!(x, y);
        assert_eq!(x, z);
        found += x.len();
    }
    assert!(found > 0);
}

/// Degenerate inputs: no triangles, all collapsed, far and very far vertices, huge radius.
#[test]
fn edge_cases_do_not_panic() {
    for (_, mut bp) in all_broads() {
        bp.update(&[], &[], &[], 0.0);
        let mut out = Vec::new();
        bp.query(&V3::zeros(), &V3::x(), 1.0, &mut out);
        assert!(out.is_empty());

        // Collapsed triangles, all at one point, no margin: cell size falls back.
        let p = vec![V3::new(0.5, 0.5, 0.5); 6];
        bp.update(&p, &p, &[[0, 1, 2], [3, 4, 5]], 0.0);
        bp.query(&V3::zeros(), &V3::repeat(1.0), 0.0, &mut out);
        assert_eq!(sorted_unique(out.clone()), vec![0, 1]);
        out.clear();

        // Far vertices (1e6 and 1e300) and a huge query radius.
        let mut v = vec![V3::zeros(), V3::x(), V3::y(), V3::zeros(), V3::x(), V3::y()];
        v.extend([V3::repeat(1e6), V3::new(1e300, -1e300, 1e300)]);
        let tris = [[0, 1, 2], [3, 4, 6], [0, 1, 7], [5, 6, 7]];
        bp.update(&v, &v, &tris, 1e-3);
        let q = V3::new(0.1, 0.1, 0.0);
        bp.query(&q, &q, 0.0, &mut out);
        assert_eq!(sorted_unique(out.clone()), vec![0, 1, 3]);
        out.clear();
        bp.query(&V3::zeros(), &V3::zeros(), 1e301, &mut out);
        assert_eq!(sorted_unique(out.clone()), vec![0, 1, 2, 3]);
        out.clear();
        bp.query(&V3::repeat(2e6), &V3::repeat(-2e6), 0.0, &mut out);
        assert!(sorted_unique(out.clone()).contains(&1));
        out.clear();
    }
}

/// The random scenes exercise the properties: many true hits, and the projection's segment
/// test rejects part of the box candidates.
#[test]
fn scenes_are_not_trivial() {
    let mut rng = Rng(11);
    let (mut truth, mut brute, mut proj) = (0usize, 0usize, 0usize);
    for _ in 0..200 {
        let n = rng.below(48);
        let s = scene(&mut rng, n);
        let mut b = BruteForce::new();
        let mut p = ProjectionBroad::new();
        b.update(&s.start, &s.end, &s.triangles, s.margin);
        p.update(&s.start, &s.end, &s.triangles, s.margin);
        for _ in 0..24 {
            let (a, e, r) = query(&mut rng, &s);
            truth += sampled_truth(&s, &a, &e, r).len();
            brute += run(&b, &a, &e, r).len();
            proj += run(&p, &a, &e, r).len();
        }
    }
    assert!(truth > 1000, "truth {truth}");
    assert!(
        proj < brute && proj >= truth,
        "truth {truth} proj {proj} brute {brute}"
    );
    eprintln!("candidates over 4800 queries: truth {truth}, projection {proj}, brute {brute}");
}
