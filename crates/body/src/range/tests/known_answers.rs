//! Known answers for the error measure [`measure_error`] (issue 23): meshes whose offset from the
//! measured surface is known exactly, so the measure's sign convention (outward positive: front
//! `Z_e − Z_r`, back `Z_r − Z_e`), its units (mesh in m, error in mm), its per-part attribution
//! and its `uncovered`/`spurious` counts are each checked against an independent answer.
//!
//! Most tests measure the parametric JIS 9AR mannequin ([`crate::build::jis_9ar`]) against its own
//! range images, rendered at 2.5 mm by [`render_views`] and decoded by [`Views::body`]. The
//! renderer and the measure share one rasteriser, so the masks agree and each sample differs only
//! by the 16-bit depth encoding, `grey = round((d − depth_offset) / depth_scale)`: the decoded
//! depth is within `depth_scale / 2` = 0.01 mm (default 0.02 mm per grey unit) of the rendered
//! one. Every change of the mesh below has an exactly known action on the rendered depth `Z_e`,
//! hence on the error, with that half quantum as the only tolerance (plus 1e-5 mm where per-sample
//! values are read from the `f32` error images). The analytic bodies (box, sphere) are given as
//! exact `f64` depth arrays, without quantisation.
//!
//! Length: eight known-answer tests sharing one fixture (the mannequin, its views and its range
//! images, built once), each with the derivation of its reference in its doc comment; split, the
//! shared fixture and its helpers would have to move to a module of their own for one user.

use std::sync::OnceLock;

use super::*;

/// Pixel size of the mannequin's range images, mm.
const PX: f64 = 2.5;

/// Resolution of the per-sample values read back from [`ErrorImage::error_mm`] (`f32`, values
/// below 100 mm: ulp ≤ 8e-6 mm), mm.
const F32_TOL: f64 = 1e-5;

/// Tolerance of sums and means in `f64` (depths of about 1000 mm, 1e5 samples), mm.
const F64_TOL: f64 = 1e-9;

/// Half the depth quantum of the rendered range images, mm (0.01 mm).
fn half_quantum() -> f64 {
    0.5 * RenderParams::default().depth_scale_mm
}

struct Fixture {
    /// The mannequin's mesh (all 17 closed parts).
    mesh: LabelledMesh,
    /// Its rendered views (with the depths before encoding).
    views: Views,
    /// Its range images, decoded.
    body: RangeBody,
    /// The mesh measured against them unchanged.
    base: ErrorReport,
}

/// The parametric JIS 9AR mannequin, its range images at 2.5 mm and its own error (built once).
fn fixture() -> &'static Fixture {
    static F: OnceLock<Fixture> = OnceLock::new();
    F.get_or_init(|| {
        let mesh = crate::build::jis_9ar().labelled_mesh();
        let views =
            render_views(&mesh, PX, &RenderParams::default()).expect("the mannequin renders");
        let body = views.body().expect("the views register");
        let base = measure_error(&body_mesh(&mesh), &body);
        Fixture {
            mesh,
            views,
            body,
            base,
        }
    })
}

/// Any labelled mesh as a [`BodyMesh`] (the measure reads positions, triangles and labels only).
fn body_mesh(m: &LabelledMesh) -> BodyMesh {
    BodyMesh {
        positions: m.vertices.iter().map(|v| [v.x, v.y, v.z]).collect(),
        triangles: m.triangles.clone(),
        triangle_part: m.triangle_part.clone(),
        vertex_part: m.vertex_part.clone(),
        pivots: Vec::new(),
        rings: Vec::new(),
    }
}

/// The mesh with every vertex mapped by `f` (m → m).
fn mapped(m: &LabelledMesh, f: impl Fn(V3, Part) -> V3) -> LabelledMesh {
    LabelledMesh {
        vertices: m
            .vertices
            .iter()
            .zip(&m.vertex_part)
            .map(|(&v, &p)| f(v, p))
            .collect(),
        ..m.clone()
    }
}

/// The mesh as a triangle soup whose triangles facing the front camera (counter-clockwise seen
/// from +z) are moved by `+d_mm` along z and all others by `−d_mm`: along every line of sight the
/// nearest surface seen by each camera moves `d_mm` towards that camera, i.e. outwards.
fn inflated_in_depth(m: &LabelledMesh, d_mm: f64) -> LabelledMesh {
    let mut out = LabelledMesh::default();
    for (t, tri) in m.triangles.iter().enumerate() {
        let [a, b, c] = tri.map(|i| m.vertices[i as usize]);
        let dz = if (b - a).cross(&(c - a)).z > 0.0 {
            d_mm * 1e-3
        } else {
            -d_mm * 1e-3
        };
        let base = out.vertices.len() as u32;
        for v in [a, b, c] {
            out.vertices.push(v + V3::new(0.0, 0.0, dz));
            out.vertex_part.push(m.triangle_part[t]);
        }
        out.triangles.push([base, base + 1, base + 2]);
        out.triangle_part.push(m.triangle_part[t]);
    }
    out
}

/// The two views of a report with the reference depths: `(front?, image, Z_r)`.
fn views<'a>(e: &'a ErrorReport, body: &'a RangeBody) -> [(bool, &'a ErrorImage, &'a [f64]); 2] {
    [(true, &e.front, &body.front), (false, &e.back, &body.back)]
}

/// Mean of the error image's compared samples, mm, and their count.
fn image_mean(im: &ErrorImage) -> (f64, usize) {
    let (s, n) = im
        .error_mm
        .iter()
        .filter(|v| !v.is_nan())
        .fold((0.0, 0), |(s, n), &v| (s + f64::from(v), n + 1));
    (s / n.max(1) as f64, n)
}

/// Baseline: the mannequin's own mesh against its own range images differs by the depth
/// quantisation only. References: per sample the outward error is the encoding residual of the
/// renderer's own depth `z` (before encoding): front `z − Z_r`, back `Z_r − z` (sign-sensitive:
/// a swapped convention differs by up to 0.02 mm); that residual is at most `depth_scale / 2` =
/// 0.01 mm (rounding to the nearest grey unit) and spread over the whole quantum (an error in m
/// instead of mm would read 1e-5 mm); nothing uncovered or spurious (one rasteriser for both).
/// Tolerance: 1e-5 mm per sample (the `f32` error image).
#[test]
fn the_mannequin_against_its_own_range_images_reads_only_the_depth_quantum() {
    let f = fixture();
    let (q, e) = (half_quantum(), &f.base);
    eprintln!(
        "baseline: {} samples, signed {:.5} ± {:.5} mm, |·| {:.5} mm, uncovered {}, spurious {}",
        e.total.samples,
        e.total.mean_signed_mm,
        e.total.sd_signed_mm,
        e.total.mean_abs_mm,
        e.uncovered,
        e.spurious
    );
    assert_eq!((e.uncovered, e.spurious), (0, 0));
    assert_eq!(e.total.samples, e.valid_samples);
    let (w, h) = (f.body.width, f.body.height);
    let mut worst = 0.0f64;
    for ((front, im, zr), view) in views(e, &f.body)
        .into_iter()
        .zip([&f.views.front, &f.views.back])
    {
        for r in 0..h {
            for c in 0..w {
                let k = r * w + c;
                let col = if front { c } else { w - 1 - c };
                let z = view.depth_mm[r * w + col];
                assert_eq!(z.is_nan(), im.error_mm[k].is_nan());
                if z.is_nan() {
                    continue;
                }
                let want = if front { z - zr[k] } else { zr[k] - z };
                let v = f64::from(im.error_mm[k]);
                assert!(
                    (v - want).abs() <= F32_TOL,
                    "front {front} ({c}, {r}): {v} vs {want}"
                );
                worst = worst.max(v.abs());
            }
        }
    }
    assert!(worst <= q + F32_TOL, "worst |Z_e − Z_r| {worst} mm");
    assert!(e.total.mean_abs_mm <= q && e.total.mean_signed_mm.abs() <= q);
    // The quantisation error is spread over the whole quantum (not a constant offset).
    assert!(worst > 0.9 * q, "worst {worst} mm");
}

/// Every front-facing triangle moved `+d` along z and every other one `−d` (a triangle soup):
/// the surface each camera sees moves `d` towards it, so every sample's outward error grows by
/// exactly `d`, in both views and every part, for `d` = 1, 5, 10 mm. (Not inwards: a soup moved
/// `−d` lets back-facing triangles come out in front wherever the body, or a part hidden inside
/// another at a joint, is thinner than `2d`; at `d` = −5 mm 3816 of 140 554 samples deviate, 3740
/// of them where the body is thinner than 10 mm. Inward offsets are checked by the translation's
/// back view, the box and the sphere.)
/// References: per sample `e(d) = e(0) + d`; per part and in total mean signed error `d` and mean
/// |error| `|d|`. Tolerances: per sample 1e-5 mm (the `f32` error image); means `depth_scale / 2`
/// = 0.01 mm against `d` (the baseline's quantisation), and 1e-9 mm for the change of the mean
/// (exact: the same triangle wins every sample, see the baseline), which also gives the
/// linearity. A flipped sign in either view, or an error in m instead of mm, fails by ≥ 1 mm.
#[test]
fn the_mannequin_moved_outward_in_depth_by_d_reads_plus_d() {
    let f = fixture();
    let (q, base) = (half_quantum(), &f.base);
    let mut means = Vec::new();
    for d in [1.0, 5.0, 10.0] {
        let e = measure_error(&body_mesh(&inflated_in_depth(&f.mesh, d)), &f.body);
        assert_eq!((e.uncovered, e.spurious), (0, 0), "d = {d}");
        assert_eq!(e.total.samples, base.total.samples);
        let mut worst = 0.0f64;
        for ((_, a, _), (_, b, _)) in views(base, &f.body).into_iter().zip(views(&e, &f.body)) {
            assert_eq!(a.part, b.part, "d = {d}: the same parts are seen");
            for (&ea, &eb) in a.error_mm.iter().zip(&b.error_mm) {
                assert_eq!(ea.is_nan(), eb.is_nan());
                if !ea.is_nan() {
                    worst = worst.max((f64::from(eb) - f64::from(ea) - d).abs());
                }
            }
        }
        eprintln!(
            "inflated by {d:5.1} mm: signed {:.5} ± {:.5} mm, |·| {:.5} mm; worst per-sample deviation from e(0) + d {worst:.1e} mm",
            e.total.mean_signed_mm, e.total.sd_signed_mm, e.total.mean_abs_mm
        );
        assert!(worst <= F32_TOL, "d = {d}: {worst}");
        assert!((e.total.mean_signed_mm - d).abs() <= q, "d = {d}");
        assert!((e.total.mean_abs_mm - d.abs()).abs() <= q, "d = {d}");
        assert!(e.total.sd_signed_mm <= q, "d = {d}");
        assert!((e.total.mean_signed_mm - base.total.mean_signed_mm - d).abs() <= F64_TOL);
        for ((p, s), (_, s0)) in e.parts.iter().zip(&base.parts) {
            assert_eq!(s.samples, s0.samples, "{p:?}");
            assert!((s.mean_signed_mm - d).abs() <= q, "{p:?} d = {d}");
            assert!((s.mean_abs_mm - d.abs()).abs() <= q, "{p:?} d = {d}");
            assert!((s.mean_signed_mm - s0.mean_signed_mm - d).abs() <= F64_TOL);
        }
        means.push((d, e.total.mean_signed_mm));
    }
    // Linear with slope 1 through the baseline.
    let slope = (means[2].1 - means[0].1) / (means[2].0 - means[0].0);
    assert!((slope - 1.0).abs() <= F64_TOL, "slope {slope}");
}

/// The whole mesh translated by `d` = 5 mm along +z (towards the front camera): the front view's
/// outward error grows by `d`, the back view's shrinks by `d` (the mesh lies `d` outside in front
/// and `d` inside behind). References: per sample `e_front = e_0 + d`, `e_back = e_0 − d`; per
/// view means `±d`; total mean signed `e_0` plus `d·(n_front − n_back)/(n_front + n_back)` (= 0:
/// the views have equal masks); total mean |error| `d`. Tolerances as for the inflated mesh:
/// 1e-5 mm per sample (`f32`), `depth_scale / 2` = 0.01 mm for means against `±d`, 1e-9 mm for
/// the exact total. Fails if the back view were not measured outward (`Z_r − Z_e`).
#[test]
fn the_mannequin_translated_in_depth_reads_plus_d_in_front_and_minus_d_behind() {
    let f = fixture();
    let (q, base) = (half_quantum(), &f.base);
    let d = 5.0;
    let e = measure_error(
        &body_mesh(&mapped(&f.mesh, |v, _| v + V3::new(0.0, 0.0, d * 1e-3))),
        &f.body,
    );
    assert_eq!((e.uncovered, e.spurious), (0, 0));
    let mut counts = Vec::new();
    for ((front, a, _), (_, b, _)) in views(base, &f.body).into_iter().zip(views(&e, &f.body)) {
        let want = if front { d } else { -d };
        let mut worst = 0.0f64;
        for (&ea, &eb) in a.error_mm.iter().zip(&b.error_mm) {
            if !ea.is_nan() {
                worst = worst.max((f64::from(eb) - f64::from(ea) - want).abs());
            }
        }
        let (mean, n) = image_mean(b);
        eprintln!(
            "translated +{d} mm in z, {} view: mean {mean:.5} mm over {n} samples; worst deviation {worst:.1e} mm",
            if front { "front" } else { "back" }
        );
        assert!(worst <= F32_TOL);
        assert!((mean - want).abs() <= q + F32_TOL, "{mean} vs {want}");
        counts.push(n as f64);
    }
    let want_total =
        base.total.mean_signed_mm + d * (counts[0] - counts[1]) / (counts[0] + counts[1]);
    eprintln!(
        "translated: total signed {:.5} mm (reference {want_total:.5}), |·| {:.5} mm",
        e.total.mean_signed_mm, e.total.mean_abs_mm
    );
    assert!((e.total.mean_signed_mm - want_total).abs() <= F64_TOL);
    assert!((e.total.mean_abs_mm - d).abs() <= q);
}

/// Each part's own depth maps `[front, back]` (front column order, NaN where the part is not
/// seen), rendered alone by the range-image renderer in the body's frame.
fn part_depths(mesh: &LabelledMesh, body: &RangeBody) -> Vec<[Vec<f64>; 2]> {
    let (w, h) = (body.width, body.height);
    let params = RenderParams {
        frame: Some(Frame {
            origin_mm: body.origin,
            width: w,
            height: h,
        }),
        ..RenderParams::default()
    };
    Part::ALL
        .iter()
        .map(|&p| {
            let triangles: Vec<[u32; 3]> = mesh
                .triangles
                .iter()
                .zip(&mesh.triangle_part)
                .filter(|(_, tp)| **tp == p)
                .map(|(t, _)| *t)
                .collect();
            let alone = LabelledMesh {
                triangle_part: vec![p; triangles.len()],
                triangles,
                ..mesh.clone()
            };
            let v = render_images(&alone, PX, &params).expect("a part renders alone");
            let mut back = vec![f64::NAN; w * h];
            for r in 0..h {
                for c in 0..w {
                    back[r * w + c] = v.back.depth_mm[r * w + (w - 1 - c)];
                }
            }
            [v.front.depth_mm, back]
        })
        .collect()
}

/// Per part `(samples, Σ signed, Σ |·|)` the measure must report when part `moved`'s depths are
/// mapped by `t` (mm → mm, increasing: a map of world z alone commutes with the z-buffer), from
/// the parts' own depths: per sample the nearest part wins (ties to the lower index, the mesh
/// order), and its depth is compared with `Z_r` outwards.
fn predicted(
    depths: &[[Vec<f64>; 2]],
    body: &RangeBody,
    moved: Part,
    t: impl Fn(f64) -> f64,
) -> [(usize, f64, f64); 17] {
    let mut acc = [(0usize, 0.0, 0.0); 17];
    for (v, zr) in [&body.front, &body.back].into_iter().enumerate() {
        let front = v == 0;
        for (k, &zr) in zr.iter().enumerate() {
            let mut best: Option<(f64, usize)> = None;
            for (i, d) in depths.iter().enumerate() {
                let z = d[v][k];
                if z.is_nan() {
                    continue;
                }
                let z = if i == moved.index() { t(z) } else { z };
                let nearer = match best {
                    None => true,
                    Some((b, _)) => (front && z > b) || (!front && z < b),
                };
                if nearer {
                    best = Some((z, i));
                }
            }
            if let (Some((z, i)), false) = (best, zr.is_nan()) {
                let e = if front { z - zr } else { zr - z };
                acc[i].0 += 1;
                acc[i].1 += e;
                acc[i].2 += e.abs();
            }
        }
    }
    acc
}

/// One part at a time (all 17) compressed in depth by `f` = 20 % towards the plane `z = z_c`
/// through its vertices' centroid (`z ↦ z_c + (1 − f)(z − z_c)`), and separately translated
/// 5 mm towards the front camera.
///
/// References: (1) on every sample the part is seen at before and after, analytically, the
/// compressed part reads `−f·h` with `h` the reference surface's outward height above the plane
/// (front `Z_r − z_c`, back `z_c − Z_r`), the translated part `+d` in front and `−d` behind;
/// tolerance `(1 − f)·depth_scale/2` resp. `depth_scale/2` (the baseline's quantisation, scaled by
/// the map) + 1e-5 mm (`f32`). (2) every part whose silhouette does not overlap the moved part's
/// keeps its baseline statistics exactly. (3) where the moved part overlaps its neighbours (the
/// parts interpenetrate at the joints) it now hides or uncovers them: accounted for by the map's
/// exact action on the moved part's own range image (rendered alone), composed with the other
/// parts' own images by the z-buffer rule; every part's sample count must match it exactly and its
/// mean signed and mean |error| within 1e-9 mm (the same rendered depths, composed in a different
/// order). A check with the identity map reproduces the baseline report.
#[test]
fn a_part_compressed_or_moved_in_depth_reads_its_analytic_error_and_others_keep_theirs() {
    let f = fixture();
    let (q, base) = (half_quantum(), &f.base);
    let depths = part_depths(&f.mesh, &f.body);
    let check = |e: &ErrorReport, want: &[(usize, f64, f64); 17], what: &str| {
        for ((p, s), &(n, ss, sa)) in e.parts.iter().zip(want) {
            let m = n.max(1) as f64;
            assert_eq!(s.samples, n, "{what}: {p:?} samples");
            assert!(
                (s.mean_signed_mm - ss / m).abs() <= F64_TOL
                    && (s.mean_abs_mm - sa / m).abs() <= F64_TOL,
                "{what}: {p:?} {} / {} vs {} / {}",
                s.mean_signed_mm,
                s.mean_abs_mm,
                ss / m,
                sa / m
            );
        }
    };
    check(
        base,
        &predicted(&depths, &f.body, Part::Head, |z| z),
        "identity",
    );
    // Each part's silhouette (front view; a closed part's back view has the same one).
    let covers = |p: Part, k: usize| !depths[p.index()][0][k].is_nan();
    let n = f.body.width * f.body.height;
    let (fr, d) = (0.2, 5.0);
    eprintln!(
        "part              samples  compressed 20 %: signed (analytic on kept)   moved +5 mm: front / back   neighbours changed"
    );
    for p in Part::ALL {
        let zs: Vec<f64> = f
            .mesh
            .vertices
            .iter()
            .zip(&f.mesh.vertex_part)
            .filter(|(_, vp)| **vp == p)
            .map(|(v, _)| v.z)
            .collect();
        let zc = zs.iter().sum::<f64>() / zs.len() as f64;
        let compress = mapped(&f.mesh, |v, vp| {
            if vp == p {
                V3::new(v.x, v.y, zc + (1.0 - fr) * (v.z - zc))
            } else {
                v
            }
        });
        let translate = mapped(&f.mesh, |v, vp| {
            if vp == p {
                v + V3::new(0.0, 0.0, d * 1e-3)
            } else {
                v
            }
        });
        let zc = zc * 1e3;
        let ec = measure_error(&body_mesh(&compress), &f.body);
        let et = measure_error(&body_mesh(&translate), &f.body);
        for e in [&ec, &et] {
            assert_eq!((e.uncovered, e.spurious), (0, 0), "{p:?}");
        }
        // (1) The analytic answer on the samples the part keeps.
        let pi = p.index() as u8;
        let (mut kept, mut sum_c, mut sum_h) = (0usize, 0.0, 0.0);
        let mut kept_t = [(0usize, 0.0); 2];
        for (v, (front, b, zr)) in views(base, &f.body).into_iter().enumerate() {
            let (c, t) = if front {
                (&ec.front, &et.front)
            } else {
                (&ec.back, &et.back)
            };
            for (k, &zr) in zr.iter().enumerate() {
                if zr.is_nan() || b.part[k] != pi {
                    continue;
                }
                if c.part[k] == pi {
                    let h = if front { zr - zc } else { zc - zr };
                    let e = f64::from(c.error_mm[k]);
                    assert!(
                        (e + fr * h).abs() <= (1.0 - fr) * q + F32_TOL,
                        "{p:?} compressed: {e} vs {} at sample {k}",
                        -fr * h
                    );
                    kept += 1;
                    sum_c += e;
                    sum_h += -fr * h;
                }
                if t.part[k] == pi {
                    let want = if front { d } else { -d };
                    let e = f64::from(t.error_mm[k]);
                    assert!(
                        (e - want).abs() <= q + F32_TOL,
                        "{p:?} moved: {e} at sample {k}"
                    );
                    kept_t[v].0 += 1;
                    kept_t[v].1 += e;
                }
            }
        }
        // (2) Parts not overlapping the moved one keep their statistics exactly; (3) all parts
        // match the composed prediction.
        let mut changed = Vec::new();
        for o in Part::ALL {
            let overlaps = o == p || (0..n).any(|k| covers(p, k) && covers(o, k));
            for e in [&ec, &et] {
                if !overlaps {
                    assert_eq!(
                        e.parts[o.index()],
                        base.parts[o.index()],
                        "{o:?} ({p:?} moved)"
                    );
                } else if o != p && e.parts[o.index()] != base.parts[o.index()] {
                    let s = (e.parts[o.index()].1, base.parts[o.index()].1);
                    changed.push(format!(
                        "{}:{} {:+.3}",
                        if std::ptr::eq(e, &ec) { "c" } else { "t" },
                        o.name(),
                        s.0.mean_signed_mm - s.1.mean_signed_mm
                    ));
                }
            }
        }
        check(
            &ec,
            &predicted(&depths, &f.body, p, |z| zc + (1.0 - fr) * (z - zc)),
            &format!("{p:?} compressed"),
        );
        check(
            &et,
            &predicted(&depths, &f.body, p, |z| z + d),
            &format!("{p:?} moved"),
        );
        let (sc, st) = (ec.parts[p.index()].1, et.parts[p.index()].1);
        eprintln!(
            "{:16} {:6}  {:8.3} mm ({:8.3} on {:5} kept)   {:.3} / {:.3} mm ({} / {} kept)   {}",
            p.name(),
            base.parts[p.index()].1.samples,
            sc.mean_signed_mm,
            sum_h / kept.max(1) as f64,
            kept,
            kept_t[0].1 / kept_t[0].0.max(1) as f64,
            kept_t[1].1 / kept_t[1].0.max(1) as f64,
            kept_t[0].0,
            kept_t[1].0,
            changed.join(", ")
        );
        // The part keeps most of its samples; the kept samples' mean is the analytic one.
        assert!(kept as f64 > 0.5 * base.parts[p.index()].1.samples as f64);
        assert!((sum_c - sum_h).abs() / kept as f64 <= (1.0 - fr) * q + F32_TOL);
        assert!(st.mean_abs_mm > 0.5 * d && sc.mean_signed_mm < 0.0, "{p:?}");
    }
}

/// Samples of a view's mask, row by row: `mask(c, r)` is valid.
fn mask(z: &[f64], w: usize) -> impl Fn(isize, usize) -> bool + '_ {
    move |c, r| c >= 0 && (c as usize) < w && !z[r * w + c as usize].is_nan()
}

/// The mesh shifted sideways (+x) by `k` = 0, 1, 2, 4, 7 pixel widths. References: (exact) a
/// shift by whole pixels shifts the rendered mask by `k` columns, so `uncovered` = Σ over views of
/// the reference samples whose column `c − k` is empty, `spurious` = the empty samples whose
/// column `c − k` is valid, and `k = 0` is the baseline (0, 0); (approximate) each horizontal run
/// of valid samples loses its first `k` samples and gains `k` beyond its end, so both counts are
/// `k·R` with `R` the runs in both views (`R = 2·H` for a convex silhouette `H` rows high), less
/// `k − L` for runs shorter than `k` and `k − g` for gaps shorter than `k`. Tolerance: none on
/// the exact counts; the approximate rule's bracket is computed per row. Per sample, the rendered
/// mask must be the reference mask moved `k` columns towards +x in both views (both stored in the
/// front's column order; a mirrored back view or a shift in m instead of mm fails), and on the
/// samples still compared the error must be the unshifted rendered depth `z` at column `c − k`
/// against `Z_r` at `c`, outwards (front `z − Z_r`, back `Z_r − z`); tolerance 1e-5 mm + 1e-6
/// relative (the `f32` error image; near the silhouette the error reaches tens of mm).
#[test]
fn a_sideways_shift_by_k_pixels_uncovers_and_adds_the_predicted_samples() {
    let f = fixture();
    let (w, h) = (f.body.width, f.body.height);
    let masks = [mask(&f.body.front, w), mask(&f.body.back, w)];
    // Runs per row and the shortfall bracket of the k·R rule.
    let runs = |k: isize| -> (usize, usize, usize) {
        let (mut runs, mut short, mut rows) = (0, 0, 0);
        for m in &masks {
            for r in 0..h {
                let mut c = 0isize;
                let mut last_end: Option<isize> = None;
                let mut any = false;
                while c < w as isize {
                    if !m(c, r) {
                        c += 1;
                        continue;
                    }
                    let s = c;
                    while m(c, r) {
                        c += 1;
                    }
                    any = true;
                    runs += 1;
                    short += (k - (c - s)).max(0) as usize;
                    if let Some(e) = last_end {
                        short += (k - (s - e)).max(0) as usize;
                    }
                    last_end = Some(c);
                }
                rows += usize::from(any);
            }
        }
        (runs, short, rows)
    };
    for k in [0isize, 1, 2, 4, 7] {
        // The shifted silhouette stays in the frame.
        assert!((0..h).all(|r| ((w as isize - k)..w as isize).all(|c| !masks[0](c, r))));
        let dx = k as f64 * PX * 1e-3;
        let e = measure_error(
            &body_mesh(&mapped(&f.mesh, |v, _| v + V3::new(dx, 0.0, 0.0))),
            &f.body,
        );
        let (mut unc, mut spu) = (0, 0);
        for m in &masks {
            for r in 0..h {
                for c in 0..w as isize {
                    match (m(c, r), m(c - k, r)) {
                        (true, false) => unc += 1,
                        (false, true) => spu += 1,
                        _ => {}
                    }
                }
            }
        }
        let (nr, short, rows) = runs(k);
        let kr = k as usize * nr;
        eprintln!(
            "shift {k} px: uncovered {} (exact {unc}), spurious {} (exact {spu}); k·R = {kr} (R = {nr} runs, bracket −{short}); naive 2·k·H = {} (H = {} rows)",
            e.uncovered,
            e.spurious,
            k as usize * rows,
            rows / 2,
        );
        let mut worst = 0.0f64;
        for (((front, im, zr), m), view) in views(&e, &f.body)
            .into_iter()
            .zip(&masks)
            .zip([&f.views.front, &f.views.back])
        {
            for r in 0..h {
                for c in 0..w {
                    let covered = !im.rendered_mm[r * w + c].is_nan();
                    assert_eq!(covered, m(c as isize - k, r), "shift {k}: ({c}, {r})");
                    let v = im.error_mm[r * w + c];
                    if v.is_nan() {
                        continue;
                    }
                    let src = c - k as usize;
                    let col = if front { src } else { w - 1 - src };
                    let z = view.depth_mm[r * w + col];
                    let want = if front {
                        z - zr[r * w + c]
                    } else {
                        zr[r * w + c] - z
                    };
                    let dev = (f64::from(v) - want).abs();
                    assert!(
                        dev <= F32_TOL + 1e-6 * want.abs(),
                        "shift {k}: {v} vs {want}"
                    );
                    worst = worst.max(dev);
                }
            }
        }
        eprintln!(
            "  compared {} samples, signed {:.3} mm, |·| {:.3} mm, worst deviation from the shifted depth {worst:.1e} mm",
            e.total.samples, e.total.mean_signed_mm, e.total.mean_abs_mm
        );
        assert_eq!((e.uncovered, e.spurious), (unc, spu), "shift {k} px");
        let floor = kr.saturating_sub(short);
        assert!(
            floor <= unc && unc <= kr,
            "shift {k} px: {unc} vs {kr} − {short}"
        );
        assert!(
            floor <= spu && spu <= kr,
            "shift {k} px: {spu} vs {kr} − {short}"
        );
        assert_eq!(e.total.samples, e.valid_samples - unc);
        if k == 0 {
            assert_eq!(e.parts, f.base.parts);
            assert_eq!(e.total, f.base.total);
        }
    }
}

/// A body given directly as exact depth arrays (no quantisation): `front`/`back` world z (mm) of
/// the solid along the line of sight through each sample, `None` where it misses.
fn analytic_body(
    width: usize,
    height: usize,
    pixel: f64,
    origin: [f64; 2],
    depth: impl Fn(f64, f64) -> Option<(f64, f64)>,
) -> RangeBody {
    let mut body = RangeBody {
        width,
        height,
        pixel_size: pixel,
        origin,
        front: vec![f64::NAN; width * height],
        back: vec![f64::NAN; width * height],
        landmarks: BTreeMap::new(),
    };
    for r in 0..height {
        for c in 0..width {
            let [x, y] = body.world(c as f64, r as f64);
            if let Some((lo, hi)) = depth(x, y) {
                body.front[r * width + c] = hi;
                body.back[r * width + c] = lo;
            }
        }
    }
    body
}

/// An axis-aligned box 20 × 30 samples (2.5 mm pixels, faces halfway between pixel centres, depth
/// −30 … 40.123 mm) given as exact range images, and box meshes. References: the same box reads
/// 0 everywhere; grown in depth by `d` on both faces (1, 5, 10, −5 mm) it reads `d` signed and
/// `|d|` absolute at every sample; shifted sideways by `k` whole pixels, `uncovered` = `spurious`
/// = `2·k·30` (k columns of 30 rows on each side of the silhouette, two views); widened by `k`
/// pixels on both sides, `spurious` = `2·2·k·30`, nothing uncovered. Tolerance 1e-9 mm (exact
/// depths, flat faces: barycentric interpolation is exact), none on the counts (the faces stay
/// half a pixel from the sample centres).
#[test]
fn an_analytic_box_reads_its_offsets_and_shifts_exactly() {
    let px = PX;
    let (w, h, origin) = (40, 50, [-50.0, 62.5]);
    // Columns 10..=29, rows 10..=39.
    let (x0, x1) = (origin[0] + 9.5 * px, origin[0] + 29.5 * px);
    let (y0, y1) = (origin[1] - 39.5 * px, origin[1] - 9.5 * px);
    let (z0, z1) = (-30.0, 40.123);
    let body = analytic_body(w, h, px, origin, |x, y| {
        (x > x0 && x < x1 && y > y0 && y < y1).then_some((z0, z1))
    });
    assert_eq!(body.valid_samples(), 2 * 20 * 30);
    let measure = |dx: [f64; 2], dz: [f64; 2]| {
        let m = box_mesh(
            [(x0 + dx[0]) * 1e-3, y0 * 1e-3, (z0 + dz[0]) * 1e-3],
            [(x1 + dx[1]) * 1e-3, y1 * 1e-3, (z1 + dz[1]) * 1e-3],
            |v| v,
        );
        measure_error(&body_mesh(&m), &body)
    };
    let e = measure([0.0; 2], [0.0; 2]);
    assert_eq!((e.uncovered, e.spurious, e.total.samples), (0, 0, 1200));
    assert!(e.total.mean_abs_mm <= F64_TOL);
    for d in [1.0, 5.0, 10.0, -5.0] {
        let e = measure([0.0; 2], [-d, d]);
        eprintln!(
            "box grown by {d} mm in depth: signed {:.12} ± {:.1e} mm, |·| {:.12} mm",
            e.total.mean_signed_mm, e.total.sd_signed_mm, e.total.mean_abs_mm
        );
        assert_eq!((e.uncovered, e.spurious, e.total.samples), (0, 0, 1200));
        assert!((e.total.mean_signed_mm - d).abs() <= F64_TOL);
        assert!((e.total.mean_abs_mm - d.abs()).abs() <= F64_TOL);
        assert!(e.total.sd_signed_mm <= 1e-6);
        let s = e.parts[Part::Chest.index()].1;
        assert_eq!(s.samples, 1200);
        assert!((s.mean_signed_mm - d).abs() <= F64_TOL);
        for (front, im, _) in views(&e, &body) {
            let (mean, n) = image_mean(im);
            assert_eq!(n, 600, "front {front}");
            assert!((mean - d).abs() <= F32_TOL, "front {front}: {mean}");
        }
    }
    for k in [1.0, 3.0, 8.0] {
        let s = measure([k * px; 2], [0.0; 2]);
        let g = measure([-k * px, k * px], [0.0; 2]);
        let kh = k as usize * 30;
        eprintln!(
            "box shifted {k} px: uncovered {}, spurious {}; widened {k} px each side: uncovered {}, spurious {}",
            s.uncovered, s.spurious, g.uncovered, g.spurious
        );
        assert_eq!((s.uncovered, s.spurious), (2 * kh, 2 * kh));
        assert_eq!(s.total.samples, 1200 - 2 * kh);
        assert!(s.total.mean_abs_mm <= F64_TOL);
        assert_eq!((g.uncovered, g.spurious), (0, 2 * 2 * kh));
        assert!(g.total.mean_abs_mm <= F64_TOL);
    }
}

/// A sphere of radius `R` = 100 mm given as exact range images (1 mm pixels, centre off the pixel
/// grid), measured with UV-sphere meshes (128 × 256) of radius `R_m` = 95, 100, 105 mm.
/// Reference: the mesh is a convex polyhedron inscribed in the sphere of radius `R_m` and
/// containing the concentric ball of radius `R_in = R_m·cos γ` (`γ` its longest edge's angle: a
/// point of a face is a convex combination of its vertices, so its projection on any vertex
/// direction is at least `R_m·cos γ`). Hence at a sample at distance `ρ` from the axis the outward
/// error lies in `[√(R_in² − ρ²)⁺ − √(R² − ρ²), √(R_m² − ρ²) − √(R² − ρ²)]` (front and back,
/// by the mesh's symmetry about `z = z_c`), and its mean within the means of those bounds; the
/// mesh covers every sample with `ρ < R_in` and none with `ρ > R_m`, which brackets `uncovered`
/// and `spurious` (two views each). The bracket is the tolerance: it is the polyhedron's own
/// chord error (`R_m − R_in` ≈ 0.06 mm), nothing is added. The upper bound's mean over the
/// covered disc of radius `a = min(R, R_m)`, `(2/3a²)·[(R_m³ − (R_m² − a²)^{3/2}) − (R³ − (R² −
/// a²)^{3/2})]`, is printed for comparison (+8.32 mm at `R_m` = 105 mm, −8.29 mm at 95 mm: more
/// than `|R_m − R|` because the lines of sight meet the rim obliquely).
#[test]
fn an_analytic_sphere_reads_its_radius_change() {
    let (r0, c) = (100.0, [0.3, 1000.7, 20.0]);
    let (w, h, origin) = (221, 221, [-110.0, 1110.0]);
    let body = analytic_body(w, h, 1.0, origin, |x, y| {
        let rho2 = (x - c[0]).powi(2) + (y - c[1]).powi(2);
        (rho2 < r0 * r0).then(|| {
            let dz = (r0 * r0 - rho2).sqrt();
            (c[2] - dz, c[2] + dz)
        })
    });
    let centre = V3::new(c[0], c[1], c[2]) * 1e-3;
    for rm in [95.0, 100.0, 105.0] {
        let m = sphere_mesh(centre, rm * 1e-3, 128, 256);
        // The longest edge's angle.
        let mut gamma = 0.0f64;
        for t in &m.triangles {
            for k in 0..3 {
                let (a, b) = (
                    m.vertices[t[k] as usize] - centre,
                    m.vertices[t[(k + 1) % 3] as usize] - centre,
                );
                gamma = gamma.max(a.angle(&b));
            }
        }
        let rin = rm * gamma.cos();
        let e = measure_error(&body_mesh(&m), &body);
        let (mut lo_sum, mut hi_sum, mut n) = (0.0, 0.0, 0usize);
        let (mut unc, mut spu) = ([0usize; 2], [0usize; 2]);
        for (_, im, zr) in views(&e, &body) {
            for r in 0..h {
                for col in 0..w {
                    let k = r * w + col;
                    let [x, y] = body.world(col as f64, r as f64);
                    let rho2 = (x - c[0]).powi(2) + (y - c[1]).powi(2);
                    let inside_ref = !zr[k].is_nan();
                    assert_eq!(inside_ref, rho2 < r0 * r0);
                    // Bracket of the coverage.
                    if inside_ref && rho2 > rin * rin {
                        unc[1] += 1;
                        if rho2 > rm * rm {
                            unc[0] += 1;
                        }
                    }
                    if !inside_ref && rho2 <= rm * rm {
                        spu[1] += 1;
                        if rho2 < rin * rin {
                            spu[0] += 1;
                        }
                    }
                    let v = im.error_mm[k];
                    if v.is_nan() {
                        continue;
                    }
                    let dr = (r0 * r0 - rho2).sqrt();
                    let lo = (rin * rin - rho2).max(0.0).sqrt() - dr;
                    let hi = (rm * rm - rho2).max(0.0).sqrt() - dr;
                    let v = f64::from(v);
                    assert!(
                        v >= lo - F32_TOL && v <= hi + F32_TOL,
                        "R_m {rm}: {v} not in [{lo}, {hi}] at ρ = {}",
                        rho2.sqrt()
                    );
                    lo_sum += lo;
                    hi_sum += hi;
                    n += 1;
                }
            }
        }
        let (lo, hi) = (lo_sum / n as f64, hi_sum / n as f64);
        // Mean of the upper bound over the disc the mesh covers (radius a = min(R, R_m)):
        // ∫₀ᵃ √(S² − ρ²) ρ dρ = (S³ − (S² − a²)^{3/2}) / 3.
        let a = r0.min(rm);
        let cap = |s: f64| (s.powi(3) - (s * s - a * a).powf(1.5)) / 3.0;
        let disc = 2.0 / (a * a) * (cap(rm) - cap(r0));
        eprintln!(
            "sphere R 100 mm, mesh R_m {rm} mm (R_in {rin:.3} mm): signed {:.4} mm in [{lo:.4}, {hi:.4}] (disc integral {disc:.4}), |·| {:.4} mm; uncovered {} in [{}, {}], spurious {} in [{}, {}]",
            e.total.mean_signed_mm,
            e.total.mean_abs_mm,
            e.uncovered,
            unc[0],
            unc[1],
            e.spurious,
            spu[0],
            spu[1]
        );
        assert_eq!(n, e.total.samples);
        assert!(lo - F64_TOL <= e.total.mean_signed_mm && e.total.mean_signed_mm <= hi + F64_TOL);
        assert!((unc[0]..=unc[1]).contains(&e.uncovered));
        assert!((spu[0]..=spu[1]).contains(&e.spurious));
        // Sign and size: outside by about 5 mm (more at the rim), inside by about 5 mm, or on it.
        let s = e.total.mean_signed_mm;
        if rm > r0 {
            assert!(s > 5.0 && s < 9.0 && e.spurious > 1000, "{s}");
        } else if rm < r0 {
            assert!(s < -5.0 && e.uncovered > 1000, "{s}");
        } else {
            assert!(s <= 0.0 && s > -0.1, "{s}");
        }
    }
}

/// The pipeline's own mesh: the synthetic mannequin's range images gridded at 5 mm by
/// [`grid_body`] (a discretisation error of about a millimetre), then moved outward in depth by
/// `d` = 1, 5, 10 mm as a triangle soup (front-facing triangles `+d`, the others `−d`).
/// Reference: per sample the error grows by exactly `d` and the masks do not change, so the mean
/// signed error grows by exactly `d` over the baseline's; the mean |error| grows by at most `d`.
/// Tolerance: 1e-9 mm on the means (exact in `f64`), 1e-5 mm per sample (`f32` image); none on
/// the counts.
#[test]
fn the_gridded_body_moved_outward_by_d_reads_d_more() {
    let body = synthetic::Mannequin::jis_9ar().body(5.0);
    let (mesh, _) = grid_body(&body, &BodyGridParams::default()).expect("the body grids");
    let lm = labelled(&mesh);
    let base = measure_error(&mesh, &body);
    for d in [1.0, 5.0, 10.0] {
        let e = measure_error(&body_mesh(&inflated_in_depth(&lm, d)), &body);
        let mut worst = 0.0f64;
        let mut off = 0usize;
        for ((_, a, _), (_, b, _)) in views(&base, &body).into_iter().zip(views(&e, &body)) {
            for (&ea, &eb) in a.error_mm.iter().zip(&b.error_mm) {
                assert_eq!(ea.is_nan(), eb.is_nan());
                if !ea.is_nan() {
                    let dev = (f64::from(eb) - f64::from(ea) - d).abs();
                    worst = worst.max(dev);
                    off += usize::from(dev > F32_TOL);
                }
            }
        }
        eprintln!(
            "gridded body inflated by {d} mm: signed {:.5} → {:.5} mm, |·| {:.5} → {:.5} mm; {off} samples off by > 1e-5 mm (worst {worst:.1e})",
            base.total.mean_signed_mm,
            e.total.mean_signed_mm,
            base.total.mean_abs_mm,
            e.total.mean_abs_mm
        );
        assert_eq!(
            (e.uncovered, e.spurious, e.total.samples),
            (base.uncovered, base.spurious, base.total.samples)
        );
        assert!(worst <= F32_TOL, "{off} samples, worst {worst}");
        assert!((e.total.mean_signed_mm - base.total.mean_signed_mm - d).abs() <= F64_TOL);
        assert!(e.total.mean_abs_mm <= base.total.mean_abs_mm + d + F64_TOL);
        assert!(e.total.mean_abs_mm >= d - base.total.mean_abs_mm - F64_TOL);
    }
}
