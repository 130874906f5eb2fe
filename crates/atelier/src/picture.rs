//! Pictures without a GPU: a small orthographic z-buffer renderer (no maintained
//! software-rasteriser crate fits, see `dependencies.md`) — flat-shaded triangles coloured per
//! triangle, seen from the front, the back or the body's left side, scaled to fit — and PNG
//! output written atomically. The figure sets of `xtask` and the pipeline's pictures use it.

use std::path::Path;

/// Which way the camera looks (frame: x = the body's left, y up, z forward).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum View {
    /// From the front, looking along −z (the body's left on the viewer's right).
    Front,
    /// From behind, looking along +z.
    Back,
    /// From the body's left, looking along −x (the body's front on the viewer's left).
    Left,
}

/// The fitting of a scene into an image: pixels per metre and the centre.
#[derive(Clone, Copy, Debug)]
pub struct Fit {
    scale: f64,
    centre: [f64; 2],
}

impl Fit {
    /// Fit the given screen-plane box (`lo`, `hi` in view coordinates) into `w × h` with a margin.
    pub fn new(lo: [f64; 2], hi: [f64; 2], w: usize, h: usize) -> Self {
        let scale = (0.94 * w as f64 / (hi[0] - lo[0]).max(1e-9))
            .min(0.94 * h as f64 / (hi[1] - lo[1]).max(1e-9));
        Self {
            scale,
            centre: [0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1])],
        }
    }

    /// A fitting of `scale` pixels per metre with the view point `centre` at the picture's
    /// centre.
    pub fn with_scale(scale: f64, centre: [f64; 2]) -> Self {
        Self { scale, centre }
    }
}

/// View coordinates of a point: (screen x to the right, screen y up, depth towards the camera).
pub fn to_view(p: [f64; 3], view: View) -> [f64; 3] {
    match view {
        View::Front => [p[0], p[1], p[2]],
        View::Back => [-p[0], p[1], -p[2]],
        View::Left => [-p[2], p[1], p[0]],
    }
}

/// The screen-plane box of points seen from `view`.
pub fn screen_box(points: &[[f64; 3]], view: View) -> ([f64; 2], [f64; 2]) {
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for p in points {
        let q = to_view(*p, view);
        for k in 0..2 {
            lo[k] = lo[k].min(q[k]);
            hi[k] = hi[k].max(q[k]);
        }
    }
    (lo, hi)
}

/// Render: RGB per pixel (`None` = background), `w × h`, row 0 at the top. Each triangle is
/// shaded by how squarely it faces the viewer.
pub fn render(
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    colour: &dyn Fn(usize) -> [f64; 3],
    view: View,
    fit: Fit,
    w: usize,
    h: usize,
) -> Vec<Option<[f64; 3]>> {
    render_lit(positions, triangles, colour, view, fit, (w, h), None)
}

/// [`render`] with a light: with `light` (a direction in the view's frame — screen x right,
/// y up, z towards the viewer — pointing towards the light) a triangle's shade is
/// `0.3 + 0.7 · max(0, n · l)`; without, `0.25 + 0.75 · n_z` (lit from the viewer).
pub fn render_lit(
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    colour: &dyn Fn(usize) -> [f64; 3],
    view: View,
    fit: Fit,
    (w, h): (usize, usize),
    light: Option<[f64; 3]>,
) -> Vec<Option<[f64; 3]>> {
    let view_points: Vec<[f64; 3]> = positions.iter().map(|&p| to_view(p, view)).collect();
    let ids = rasterise(&view_points, triangles, fit, w, h);
    // One colour per triangle, shaded (the pixels look them up).
    let rgb: Vec<[f64; 3]> = triangles
        .iter()
        .enumerate()
        .map(|(t, tri)| {
            let shade = triangle_shade(tri.map(|k| view_points[k as usize]), light);
            colour(t).map(|v| v * shade)
        })
        .collect();
    ids.iter().map(|id| id.map(|t| rgb[t as usize])).collect()
}

/// The shade of a triangle (corners in a view's frame) as [`render_lit`] draws it: lit by
/// `light` (any length; towards the light), or from the viewer without one.
pub fn triangle_shade([a, b, c]: [[f64; 3]; 3], light: Option<[f64; 3]>) -> f64 {
    let n = cross(sub(b, a), sub(c, a));
    let len = dot(n, n).sqrt().max(1e-300);
    match light {
        None => 0.25 + 0.75 * n[2] / len,
        Some(l) => 0.3 + 0.7 * (dot(n, l) / (len * dot(l, l).sqrt().max(1e-300))).max(0.0),
    }
}

/// The front-most triangle at each pixel centre (`None`: nothing), `w × h`, row 0 at the top,
/// of points already in a view's frame (screen x right, y up, depth towards the viewer).
/// Triangles facing away from the viewer are skipped.
pub fn rasterise(
    view_points: &[[f64; 3]],
    triangles: &[[u32; 3]],
    fit: Fit,
    w: usize,
    h: usize,
) -> Vec<Option<u32>> {
    let mut depth = vec![f64::NEG_INFINITY; w * h];
    let mut out = vec![None; w * h];
    if w == 0 || h == 0 {
        return out;
    }
    let project = |q: [f64; 3]| -> [f64; 3] {
        [
            0.5 * w as f64 + (q[0] - fit.centre[0]) * fit.scale,
            0.5 * h as f64 - (q[1] - fit.centre[1]) * fit.scale,
            q[2],
        ]
    };
    for (ti, t) in triangles.iter().enumerate() {
        let [a, b, c] = t.map(|k| view_points[k as usize]);
        let n = cross(sub(b, a), sub(c, a));
        if dot(n, n) == 0.0 || n[2] <= 0.0 || !n[2].is_finite() {
            continue;
        }
        let [pa, pb, pc] = [a, b, c].map(project);
        let area = edge(pa, pb, pc);
        if area.abs() < 1e-12 {
            continue;
        }
        let (xl, xh) = (pa[0].min(pb[0]).min(pc[0]), pa[0].max(pb[0]).max(pc[0]));
        let (yl, yh) = (pa[1].min(pb[1]).min(pc[1]), pa[1].max(pb[1]).max(pc[1]));
        if xh < 0.0 || yh < 0.0 || xl > w as f64 || yl > h as f64 {
            continue;
        }
        let x0 = xl.floor().max(0.0) as usize;
        let x1 = (xh.ceil().max(0.0) as usize).min(w - 1);
        let y0 = yl.floor().max(0.0) as usize;
        let y1 = (yh.ceil().max(0.0) as usize).min(h - 1);
        for y in y0..=y1 {
            for x in x0..=x1 {
                let q = [x as f64 + 0.5, y as f64 + 0.5, 0.0];
                let l = [
                    edge(pb, pc, q) / area,
                    edge(pc, pa, q) / area,
                    edge(pa, pb, q) / area,
                ];
                if l.iter().any(|&v| v < 0.0) {
                    continue;
                }
                let z = l[0] * pa[2] + l[1] * pb[2] + l[2] * pc[2];
                let k = y * w + x;
                if z > depth[k] {
                    depth[k] = z;
                    out[k] = Some(ti as u32);
                }
            }
        }
    }
    out
}

fn edge(a: [f64; 3], b: [f64; 3], p: [f64; 3]) -> f64 {
    (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0])
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// Bytes of a colour with components in [0, 1].
pub fn to_bytes(c: [f64; 3]) -> [u8; 3] {
    c.map(|v| (v.clamp(0.0, 1.0) * 255.0).round() as u8)
}

/// Write an RGB picture (`w × h`, row 0 at the top; `None` pixels take `background`) as a PNG,
/// atomically (a temporary file beside `path`, renamed when complete).
pub fn write_png(
    path: &Path,
    pixels: &[Option<[f64; 3]>],
    w: usize,
    h: usize,
    background: [f64; 3],
) -> std::io::Result<()> {
    let mut bytes = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut bytes, w as u32, h as u32);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        let mut writer = enc.write_header().map_err(std::io::Error::other)?;
        let data: Vec<u8> = pixels
            .iter()
            .flat_map(|p| to_bytes(p.unwrap_or(background)))
            .collect();
        writer
            .write_image_data(&data)
            .map_err(std::io::Error::other)?;
    }
    atelier_files::files::write_atomic(path, &bytes)
}

/// One colour per body part index (hues spread by the golden ratio).
pub fn part_colour(index: usize) -> [f64; 3] {
    let hue = (index as f64 * 0.618_034).fract();
    hsv(hue, 0.55, 0.95)
}

fn hsv(h: f64, s: f64, v: f64) -> [f64; 3] {
    let i = (h * 6.0).floor();
    let f = h * 6.0 - i;
    let (p, q, t) = (v * (1.0 - s), v * (1.0 - f * s), v * (1.0 - (1.0 - f) * s));
    match i as i32 % 6 {
        0 => [v, t, p],
        1 => [q, v, p],
        2 => [p, v, t],
        3 => [p, q, v],
        4 => [t, p, v],
        _ => [v, p, q],
    }
}

/// A triangle mesh by reference: vertex positions (m) and triangles.
pub type MeshRef<'a> = (&'a [[f64; 3]], &'a [[u32; 3]]);

/// Colour of the cloth in the pipeline's pictures.
pub const CLOTH: [f64; 3] = [0.85, 0.35, 0.25];
/// Colour of the body.
pub const BODY: [f64; 3] = [0.75, 0.75, 0.78];

/// The final state as the pipeline draws it: front (left half) and left side (right half) of
/// the cloth, with the body when there is one, in distinct colours, shaded, one scale for both
/// views. Returns the pixels of a `2w × h` picture.
pub fn garment_views(
    cloth: MeshRef<'_>,
    body: Option<MeshRef<'_>>,
    w: usize,
    h: usize,
) -> Vec<Option<[f64; 3]>> {
    // One scene: cloth triangles first, then the body's, indices shifted.
    let mut points: Vec<[f64; 3]> = cloth.0.to_vec();
    let mut triangles: Vec<[u32; 3]> = cloth.1.to_vec();
    let n_cloth = triangles.len();
    if let Some((bp, bt)) = body {
        let base = points.len() as u32;
        points.extend_from_slice(bp);
        triangles.extend(bt.iter().map(|t| t.map(|k| k + base)));
    }
    // Cloth seen from inside (its back faces) is drawn too: a garment's inside shows at the hem.
    let mut two_sided = triangles.clone();
    two_sided.extend(triangles[..n_cloth].iter().map(|t| [t[0], t[2], t[1]]));
    let colour = |t: usize| {
        if t < n_cloth || t >= triangles.len() {
            CLOTH
        } else {
            BODY
        }
    };
    let mut span = [0.0f64; 2];
    for view in [View::Front, View::Left] {
        let (lo, hi) = screen_box(&points, view);
        span = [span[0].max(hi[0] - lo[0]), span[1].max(hi[1] - lo[1])];
    }
    let mut out = vec![None; 2 * w * h];
    for (k, view) in [View::Front, View::Left].into_iter().enumerate() {
        let (lo, hi) = screen_box(&points, view);
        let c = [0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1])];
        let fit = Fit::new(
            [c[0] - 0.5 * span[0], c[1] - 0.5 * span[1]],
            [c[0] + 0.5 * span[0], c[1] + 0.5 * span[1]],
            w,
            h,
        );
        let pixels = render(&points, &two_sided, &colour, view, fit, w, h);
        for y in 0..h {
            for x in 0..w {
                out[y * 2 * w + k * w + x] = pixels[y * w + x];
            }
        }
    }
    out
}

/// Colour of the plane under a wet cloth.
pub const PLANE: [f64; 3] = [0.55, 0.6, 0.68];

/// A colour for a height `t` in [0, 1]: dark blue (on the plane) through teal to yellow.
pub fn height_colour(t: f64) -> [f64; 3] {
    let t = t.clamp(0.0, 1.0);
    [
        0.15 + 0.85 * t * t,
        0.2 + 0.7 * t,
        0.55 + 0.3 * t - 0.65 * t * t,
    ]
}

/// A wet cloth (z up, on the plane z = 0, `size` its side) as two views, one scale: on the
/// left seen from 35° above the plane and 30° round from −y, with the plane; on the right from
/// straight above, coloured by height (dark on the plane, yellow at the top, the scale's top
/// `top` metres) and shaded by slope, so that folds show. Returns the pixels of a `2w × h`
/// picture.
pub fn wet_views(
    cloth: MeshRef<'_>,
    size: f64,
    top: f64,
    w: usize,
    h: usize,
) -> Vec<Option<[f64; 3]>> {
    let (points, triangles) = cloth;
    let half = 0.6 * size;
    // The plane: a square under the cloth, as two triangles after the cloth's.
    let mut pts: Vec<[f64; 3]> = points.to_vec();
    let base = pts.len() as u32;
    let z = -0.002 * size;
    pts.extend_from_slice(&[
        [-half, -half, z],
        [half, -half, z],
        [half, half, z],
        [-half, half, z],
    ]);
    let n_cloth = triangles.len();
    let mut tris: Vec<[u32; 3]> = triangles.to_vec();
    tris.extend_from_slice(&[[base, base + 1, base + 2], [base, base + 2, base + 3]]);
    // Both sides of the cloth.
    let mut two_sided = tris.clone();
    two_sided.extend(triangles.iter().map(|t| [t[0], t[2], t[1]]));
    let cloth_of = |t: usize| t < n_cloth || t >= n_cloth + 2;
    let (e, a) = (35f64.to_radians(), 30f64.to_radians());
    let oblique = |p: &[f64; 3]| {
        let (x, y) = (
            p[0] * a.cos() - p[1] * a.sin(),
            p[0] * a.sin() + p[1] * a.cos(),
        );
        [
            x,
            p[2] * e.cos() + y * e.sin(),
            -y * e.cos() + p[2] * e.sin(),
        ]
    };
    let mut out = vec![None; 2 * w * h];
    // Left: oblique.
    let view: Vec<[f64; 3]> = pts.iter().map(oblique).collect();
    let (lo, hi) = screen_box(&view, View::Front);
    let fit = Fit::new(lo, hi, w, h);
    let colour = |t: usize| if cloth_of(t) { CLOTH } else { PLANE };
    let left = render(&view, &two_sided, &colour, View::Front, fit, w, h);
    // Right: from above, coloured by height.
    let heights: Vec<f64> = two_sided
        .iter()
        .map(|t| t.iter().map(|&k| pts[k as usize][2]).sum::<f64>() / 3.0)
        .collect();
    let (lo, hi) = screen_box(&pts, View::Front);
    let fit = Fit::new(lo, hi, w, h);
    let colour = |t: usize| {
        if cloth_of(t) {
            height_colour(heights[t] / top.max(1e-9))
        } else {
            PLANE
        }
    };
    let right = render(&pts, &two_sided, &colour, View::Front, fit, w, h);
    for y in 0..h {
        for x in 0..w {
            out[y * 2 * w + x] = left[y * w + x];
            out[y * 2 * w + w + x] = right[y * w + x];
        }
    }
    out
}
