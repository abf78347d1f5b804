//! Animated GIFs of a run, drawn with tiny-skia and encoded with `gif`: the arm link by link
//! coloured by joint torque, the reference path, the tip's trace, obstacles and channels, and a
//! progress bar (the picture of the page's viewer at its opening view, without text).

use crate::error::ViewError;
use crate::view::{Obstacle, RunView, count, positive};
use std::io::Write;
use tiny_skia::{
    Color, FillRule, LineCap, Paint, PathBuilder, Pixmap, Rect, Stroke, StrokeDash, Transform,
};

/// The most frames a GIF may have.
pub const MAX_FRAMES: usize = 2_000;
/// The largest width or height (pixels).
pub const MAX_SIDE: u32 = 2_000;
/// The most pixels a GIF's frames may hold together, frames times width times height (about
/// half a minute of drawing: 100 frames of 2000 x 2000 pixels took 5.7 s).
pub const MAX_PIXELS: f64 = 2e9;

/// How a GIF is drawn.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GifOptions {
    /// Width (pixels).
    pub width: u32,
    /// Height (pixels).
    pub height: u32,
    /// Frames a second of the animation.
    pub fps: u32,
    /// Seconds of the run a second of the animation shows (1 is real time).
    pub speed: f64,
}

impl Default for GifOptions {
    fn default() -> Self {
        Self {
            width: 480,
            height: 360,
            fps: 20,
            speed: 1.0,
        }
    }
}

impl GifOptions {
    /// Checks the sizes (1 to [`MAX_SIDE`] pixels), the rate (1 to 50 frames a second: GIF
    /// delays are hundredths of a second) and the speed (finite, positive).
    pub fn check(&self) -> Result<(), ViewError> {
        for (what, side) in [("gif width", self.width), ("gif height", self.height)] {
            if side == 0 || side > MAX_SIDE {
                return Err(count(what, side as usize, "pixels", 1, MAX_SIDE as usize));
            }
        }
        if !(1..=50).contains(&self.fps) {
            return Err(count("gif fps", self.fps as usize, "", 1, 50));
        }
        positive("gif speed", &[self.speed], f64::MAX)?;
        Ok(())
    }
}

/// An orthographic camera (the viewer's, `viewer.js`): yaw about z and pitch above the horizon
/// (degrees), the world point at the centre, pixels per metre.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    /// Turn about the vertical z axis (degrees).
    pub yaw: f64,
    /// Angle above the horizon (degrees); 90 looks straight down.
    pub pitch: f64,
    /// The world point at the centre of the picture (m).
    pub target: [f64; 3],
    /// Pixels a metre.
    pub scale: f64,
    /// Picture width and height (pixels).
    pub size: [f64; 2],
}

impl Camera {
    /// The camera that shows `points` whole: a planar run from above (x right, y up) fitting
    /// its bounding box, a spatial one from the viewer's `iso` view fitting its bounding sphere.
    pub fn fit(points: &[[f64; 3]], dims: usize, width: f64, height: f64) -> Camera {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for p in points {
            for i in 0..3 {
                lo[i] = lo[i].min(p[i]);
                hi[i] = hi[i].max(p[i]);
            }
        }
        if lo[0] > hi[0] {
            (lo, hi) = ([-1.0; 3], [1.0; 3]);
        }
        let target = [0, 1, 2].map(|i| 0.5 * (lo[i] + hi[i]));
        let span = [0, 1, 2].map(|i| (hi[i] - lo[i]).max(1e-6));
        let (yaw, pitch, scale) = if dims == 3 {
            let radius = 0.5 * (span[0].hypot(span[1])).hypot(span[2]);
            (-35.0, 25.0, 0.92 * width.min(height) / (2.0 * radius))
        } else {
            (0.0, 90.0, 0.88 * (width / span[0]).min(height / span[1]))
        };
        Camera {
            yaw,
            pitch,
            target,
            scale,
            size: [width, height],
        }
    }

    /// The screen position (pixels) and depth (towards the viewer, m) of world point `p`.
    pub fn project(&self, p: [f64; 3]) -> [f64; 3] {
        let (sy, cy) = self.yaw.to_radians().sin_cos();
        let (sp, cp) = self.pitch.to_radians().sin_cos();
        let d = [0, 1, 2].map(|i| p[i] - self.target[i]);
        let dot = |u: [f64; 3]| u[0] * d[0] + u[1] * d[1] + u[2] * d[2];
        [
            0.5 * self.size[0] + self.scale * dot([cy, sy, 0.0]),
            0.5 * self.size[1] - self.scale * dot([-sy * sp, cy * sp, cp]),
            dot([sy * cp, -cy * cp, sp]),
        ]
    }
}

/// The colour of a link whose joint torque is `ratio` of its limit (`torqueColour` of the
/// viewer): blue at rest, green, amber, red at the limit, dark red beyond.
pub fn torque_colour(ratio: f64) -> [u8; 3] {
    const STOPS: [(f64, [f64; 3]); 4] = [
        (0.0, [49.0, 99.0, 170.0]),
        (0.4, [44.0, 160.0, 44.0]),
        (0.7, [240.0, 170.0, 20.0]),
        (1.0, [214.0, 39.0, 40.0]),
    ];
    let r = ratio.abs();
    if !r.is_finite() {
        return [90, 0, 0];
    }
    if r > 1.0 {
        return [120, 0, 20];
    }
    let i = STOPS.iter().position(|s| r <= s.0).unwrap_or(3).max(1);
    let ((r0, c0), (r1, c1)) = (STOPS[i - 1], STOPS[i]);
    let f = (r - r0) / (r1 - r0);
    [0, 1, 2].map(|j| (c0[j] + (c1[j] - c0[j]) * f).round() as u8)
}

/// The points of a flattened row of `dims` numbers each, as `[x, y, z]`.
fn points(row: &[f64], dims: usize) -> Vec<[f64; 3]> {
    row.chunks_exact(dims)
        .map(|c| [c[0], c[1], if dims == 3 { c[2] } else { 0.0 }])
        .collect()
}

/// The sample at or before `time` and the fraction of the way to the next.
fn sample_at(t: &[f64], time: f64) -> (usize, f64) {
    let n = t.len();
    if n == 0 || time <= t[0] {
        return (0, 0.0);
    }
    if time >= t[n - 1] {
        return (n - 1, 0.0);
    }
    let k = t.partition_point(|&s| s <= time) - 1;
    (k, (time - t[k]) / (t[k + 1] - t[k]))
}

/// Row `k` moved the fraction `f` towards row `k + 1`.
fn lerp(rows: &[Vec<f64>], (k, f): (usize, f64)) -> Vec<f64> {
    match rows.get(k + 1) {
        Some(next) if f > 0.0 => rows[k]
            .iter()
            .zip(next)
            .map(|(a, b)| a + (b - a) * f)
            .collect(),
        _ => rows[k].clone(),
    }
}

fn paint(rgb: [u8; 3], alpha: u8) -> Paint<'static> {
    let mut paint = Paint::default();
    paint.set_color(Color::from_rgba8(rgb[0], rgb[1], rgb[2], alpha));
    paint.anti_alias = true;
    paint
}

fn stroke(width: f64) -> Stroke {
    Stroke {
        width: width as f32,
        line_cap: LineCap::Round,
        ..Stroke::default()
    }
}

/// Strokes the polyline through the screen points `pts`.
fn polyline(pixmap: &mut Pixmap, pts: &[[f64; 3]], paint: &Paint<'_>, stroke: &Stroke) {
    let mut path = PathBuilder::new();
    for (i, p) in pts.iter().enumerate() {
        if i == 0 {
            path.move_to(p[0] as f32, p[1] as f32);
        } else {
            path.line_to(p[0] as f32, p[1] as f32);
        }
    }
    if let Some(path) = path.finish() {
        pixmap.stroke_path(&path, paint, stroke, Transform::identity(), None);
    }
}

fn disc(pixmap: &mut Pixmap, centre: [f64; 3], radius: f64, paint: &Paint<'_>) {
    if let Some(path) = PathBuilder::from_circle(centre[0] as f32, centre[1] as f32, radius as f32)
    {
        pixmap.fill_path(&path, paint, FillRule::Winding, Transform::identity(), None);
    }
}

/// Every world point the run draws (the arm at every sample, the reference, obstacles,
/// channels), for fitting the camera.
fn world_points(run: &RunView) -> Vec<[f64; 3]> {
    let d = run.dims;
    let mut out: Vec<[f64; 3]> = run.joints.iter().flat_map(|row| points(row, d)).collect();
    out.extend(run.tip_ref.iter().flat_map(|row| points(row, d)));
    for o in &run.obstacles {
        let (centres, half): (Vec<&Vec<f64>>, [f64; 3]) = match o {
            Obstacle::Circle { centre, radius } | Obstacle::Sphere { centre, radius } => {
                (vec![centre], [*radius; 3])
            }
            Obstacle::Capsule { a, b, radius } => (vec![a, b], [*radius; 3]),
            Obstacle::Box { centre, half } => (
                vec![centre],
                [half[0], half[1], half.get(2).copied().unwrap_or(0.0)],
            ),
        };
        for c in centres {
            let c = points(c, d)[0];
            out.push([0, 1, 2].map(|i| c[i] - half[i]));
            out.push([0, 1, 2].map(|i| c[i] + half[i]));
        }
    }
    out.extend(
        run.channels
            .iter()
            .flat_map(|c| c.points.iter().flat_map(|p| points(p, d))),
    );
    out
}

/// Draws `run` at `time` seen by `camera` into `pixmap`.
pub fn draw_frame(pixmap: &mut Pixmap, run: &RunView, camera: &Camera, time: f64) {
    pixmap.fill(Color::WHITE);
    let d = run.dims;
    let project = |p: [f64; 3]| camera.project(p);
    for c in &run.channels {
        let pts: Vec<_> = c.points.iter().map(|p| project(points(p, d)[0])).collect();
        polyline(
            pixmap,
            &pts,
            &paint([120, 170, 220], 90),
            &stroke(c.width * camera.scale),
        );
    }
    let grey = paint([110, 110, 110], 115);
    for o in &run.obstacles {
        match o {
            Obstacle::Circle { centre, radius } | Obstacle::Sphere { centre, radius } => {
                disc(
                    pixmap,
                    project(points(centre, d)[0]),
                    radius * camera.scale,
                    &grey,
                );
            }
            Obstacle::Capsule { a, b, radius } => {
                let pts = [project(points(a, d)[0]), project(points(b, d)[0])];
                polyline(pixmap, &pts, &grey, &stroke(2.0 * radius * camera.scale));
            }
            Obstacle::Box { centre, half } => {
                let c = points(centre, d)[0];
                let h = [half[0], half[1], half.get(2).copied().unwrap_or(0.0)];
                // The box's outline: the hull of its projected corners, filled.
                let mut corners: Vec<[f64; 3]> = (0..8)
                    .map(|i| {
                        let s = [i & 1, (i >> 1) & 1, (i >> 2) & 1].map(|b| 2.0 * b as f64 - 1.0);
                        project([0, 1, 2].map(|j| c[j] + s[j] * h[j]))
                    })
                    .collect();
                let hull = convex_hull(&mut corners);
                let mut path = PathBuilder::new();
                for (i, p) in hull.iter().enumerate() {
                    if i == 0 {
                        path.move_to(p[0] as f32, p[1] as f32);
                    } else {
                        path.line_to(p[0] as f32, p[1] as f32);
                    }
                }
                path.close();
                if let Some(path) = path.finish() {
                    pixmap.fill_path(&path, &grey, FillRule::Winding, Transform::identity(), None);
                }
            }
        }
    }
    let red = paint([214, 39, 40], 255);
    if !run.tip_ref.is_empty() {
        let path: Vec<_> = run
            .tip_ref
            .iter()
            .map(|p| project(points(p, d)[0]))
            .collect();
        let mut dashed = stroke(1.5);
        dashed.dash = StrokeDash::new(vec![6.0, 4.0], 0.0);
        polyline(pixmap, &path, &red, &dashed);
    }
    let at = sample_at(&run.t, time);
    let last = run.points() - 1;
    let arm: Vec<_> = points(&lerp(&run.joints, at), d)
        .into_iter()
        .map(project)
        .collect();
    let mut trace: Vec<_> = run.joints[..=at.0]
        .iter()
        .map(|row| project(points(row, d)[last]))
        .collect();
    trace.push(arm[last]);
    polyline(pixmap, &trace, &paint([44, 160, 44], 255), &stroke(1.5));
    if !run.tip_ref.is_empty() {
        let reference = project(points(&lerp(&run.tip_ref, at), d)[0]);
        let ring = PathBuilder::from_circle(reference[0] as f32, reference[1] as f32, 5.0);
        if let Some(ring) = ring {
            pixmap.stroke_path(&ring, &red, &stroke(2.0), Transform::identity(), None);
        }
    }
    let torque = (!run.joint_torque.is_empty()).then(|| lerp(&run.joint_torque, at));
    let limits: Vec<f64> = if !run.torque_limit.is_empty() {
        run.torque_limit.clone()
    } else {
        let peak = run
            .joint_torque
            .iter()
            .flatten()
            .fold(0.0f64, |m, v| m.max(v.abs()));
        vec![if peak > 0.0 { peak } else { 1.0 }; last]
    };
    let width = (0.02 * camera.scale).clamp(3.0, 9.0);
    let mut order: Vec<usize> = (0..last).collect();
    order.sort_by(|&i, &j| (arm[i][2] + arm[i + 1][2]).total_cmp(&(arm[j][2] + arm[j + 1][2])));
    for i in order {
        let colour = torque
            .as_ref()
            .map_or([31, 119, 180], |tau| torque_colour(tau[i] / limits[i]));
        polyline(pixmap, &arm[i..i + 2], &paint(colour, 255), &stroke(width));
    }
    let dark = paint([34, 34, 34], 255);
    for p in &arm {
        disc(pixmap, *p, 0.35 * width, &dark);
    }
    if let Some(base) = Rect::from_xywh(arm[0][0] as f32 - 6.0, arm[0][1] as f32 - 6.0, 12.0, 12.0)
    {
        pixmap.fill_rect(base, &dark, Transform::identity(), None);
    }
    // Progress: how far into the run this frame is.
    let (t0, t1) = (run.t[0], run.t[run.len() - 1]);
    let done = if t1 > t0 {
        ((time - t0) / (t1 - t0)).clamp(0.0, 1.0)
    } else {
        1.0
    };
    let h = camera.size[1] as f32;
    for (fraction, colour) in [(1.0, [220, 220, 220]), (done, [80, 80, 80])] {
        let w = (camera.size[0] * fraction) as f32;
        if let Some(r) = Rect::from_xywh(0.0, h - 4.0, w.max(1.0), 4.0) {
            pixmap.fill_rect(r, &paint(colour, 255), Transform::identity(), None);
        }
    }
}

/// The convex hull of 2-D screen points (Andrew's monotone chain), counter-clockwise.
fn convex_hull(pts: &mut [[f64; 3]]) -> Vec<[f64; 3]> {
    pts.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    let cross = |o: [f64; 3], a: [f64; 3], b: [f64; 3]| {
        (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    };
    let mut hull: Vec<[f64; 3]> = Vec::with_capacity(2 * pts.len());
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &[f64; 3]>> = if pass == 0 {
            Box::new(pts.iter())
        } else {
            Box::new(pts.iter().rev())
        };
        for &p in iter {
            while hull.len() >= start + 2
                && cross(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 0.0
            {
                hull.pop();
            }
            hull.push(p);
        }
        hull.pop();
    }
    hull
}

/// The GIF's palette: 6 x 7 x 6 levels of red, green and blue (252 colours), then the
/// [`GREYS`], index 255 left for "unchanged since the previous frame" (transparent).
const LEVELS: [usize; 3] = [6, 7, 6];
/// Three greys of the palette after the cube, which has no grey between black and white (its
/// red and blue levels are multiples of 51, its green ones of 42.5): the obstacles' fill over
/// white (190) and darker outlines, which the cube would turn lilac.
const GREYS: [u8; 3] = [96, 144, 190];
/// The transparent index.
const UNCHANGED: u8 = 255;
/// How far apart a colour's channels may be for it to be drawn in one of the [`GREYS`].
const GREY_SPREAD: u8 = 24;

fn palette() -> Vec<u8> {
    let mut out = Vec::with_capacity(3 * 256);
    for r in 0..LEVELS[0] {
        for g in 0..LEVELS[1] {
            for b in 0..LEVELS[2] {
                for (level, count) in [(r, LEVELS[0]), (g, LEVELS[1]), (b, LEVELS[2])] {
                    out.push((255 * level / (count - 1)) as u8);
                }
            }
        }
    }
    for grey in GREYS {
        out.extend([grey; 3]);
    }
    out.resize(3 * 256, 255);
    out
}

/// The palette index nearest an RGB colour (premultiplied over white: the pixmap is opaque): the
/// cube's, or for a grey (channels within [`GREY_SPREAD`]) the nearest of the cube's black and
/// white and the [`GREYS`].
fn index(rgba: &[u8]) -> u8 {
    let level = |c: u8, n: usize| (usize::from(c) * (n - 1) + 127) / 255;
    let [r, g, b] = [0, 1, 2].map(|i| level(rgba[i], LEVELS[i]));
    let cube = (r * LEVELS[1] * LEVELS[2] + g * LEVELS[2] + b) as u8;
    let low = rgba[0].min(rgba[1]).min(rgba[2]);
    let high = rgba[0].max(rgba[1]).max(rgba[2]);
    if high - low > GREY_SPREAD {
        return cube;
    }
    let mean = (u16::from(low) + u16::from(high)) / 2;
    let cube_size = (LEVELS[0] * LEVELS[1] * LEVELS[2]) as u8;
    let greys = [(0, 0)]
        .into_iter()
        .chain(
            GREYS
                .iter()
                .enumerate()
                .map(|(i, &v)| (cube_size + i as u8, v)),
        )
        .chain([(cube_size - 1, 255)]);
    greys
        .min_by_key(|&(_, v)| mean.abs_diff(u16::from(v)))
        .map_or(cube, |(i, _)| i)
}

/// Writes `run` as an animated GIF to `out`: frames `1 / fps` s apart showing `speed` s of the
/// run a second, from its first sample to its last, looping. The run and the options are
/// checked first; at most [`MAX_FRAMES`] frames (an error names the duration, rate and speed
/// that need more) and [`MAX_PIXELS`] pixels in all.
pub fn write_gif(run: &RunView, options: &GifOptions, out: impl Write) -> Result<(), ViewError> {
    run.check()?;
    options.check()?;
    let (t0, t1) = (run.t[0], run.t[run.len() - 1]);
    // Counted in floating point: a count beyond `usize` saturates rather than wrapping to 0.
    let needed = ((t1 - t0) / options.speed * f64::from(options.fps)).ceil() + 1.0;
    if needed.is_nan() || needed > MAX_FRAMES as f64 {
        return Err(ViewError::TooManyFrames {
            seconds: t1 - t0,
            fps: options.fps,
            speed: options.speed,
            frames: needed,
            max: MAX_FRAMES,
        });
    }
    let frames = needed as usize;
    let (w, h) = (options.width, options.height);
    let pixels = needed * f64::from(w) * f64::from(h);
    if pixels > MAX_PIXELS {
        return Err(ViewError::TooManyPixels {
            frames,
            width: w,
            height: h,
            pixels,
            max: MAX_PIXELS,
        });
    }
    let mut pixmap = Pixmap::new(w, h).ok_or(ViewError::Picture)?;
    let camera = Camera::fit(&world_points(run), run.dims, f64::from(w), f64::from(h));
    let mut encoder = gif::Encoder::new(out, w as u16, h as u16, &palette())?;
    encoder.set_repeat(gif::Repeat::Infinite)?;
    encoder.write_raw_extension(gif::AnyExtension(0xFE), &[crate::SIGNATURE.as_bytes()])?;
    let delay = (100 / options.fps) as u16;
    let mut previous: Option<Vec<u8>> = None;
    for f in 0..frames {
        let time = (t0 + f as f64 * options.speed / f64::from(options.fps)).min(t1);
        draw_frame(&mut pixmap, run, &camera, time);
        let current: Vec<u8> = pixmap.data().chunks_exact(4).map(index).collect();
        let frame = match &previous {
            None => gif::Frame {
                width: w as u16,
                height: h as u16,
                buffer: current.clone().into(),
                delay,
                ..gif::Frame::default()
            },
            Some(before) => changed_part(before, &current, w as usize, h as usize, delay),
        };
        encoder.write_frame(&frame)?;
        previous = Some(current);
    }
    Ok(())
}

/// The frame that turns `before` into `after`: the box around the pixels that changed, with
/// the unchanged ones inside it transparent (so they compress to nearly nothing).
fn changed_part(
    before: &[u8],
    after: &[u8],
    w: usize,
    h: usize,
    delay: u16,
) -> gif::Frame<'static> {
    let (mut x0, mut y0, mut x1, mut y1) = (w, h, 0, 0);
    for y in 0..h {
        for x in 0..w {
            if before[y * w + x] != after[y * w + x] {
                (x0, y0, x1, y1) = (x0.min(x), y0.min(y), x1.max(x + 1), y1.max(y + 1));
            }
        }
    }
    if x0 >= x1 {
        (x0, y0, x1, y1) = (0, 0, 1, 1);
    }
    let mut buffer = Vec::with_capacity((x1 - x0) * (y1 - y0));
    for y in y0..y1 {
        for x in x0..x1 {
            let i = y * w + x;
            buffer.push(if before[i] == after[i] {
                UNCHANGED
            } else {
                after[i]
            });
        }
    }
    gif::Frame {
        left: x0 as u16,
        top: y0 as u16,
        width: (x1 - x0) as u16,
        height: (y1 - y0) as u16,
        buffer: buffer.into(),
        delay,
        transparent: Some(UNCHANGED),
        dispose: gif::DisposalMethod::Keep,
        ..gif::Frame::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The palette's colour at index `i`.
    fn colour(i: u8) -> [u8; 3] {
        let p = palette();
        let at = 3 * usize::from(i);
        [p[at], p[at + 1], p[at + 2]]
    }

    #[test]
    fn greys_stay_grey_and_colours_keep_the_cube() {
        // The obstacles' fill (110 at alpha 115 over white), which the cube alone draws lilac
        // (204, 170, 204).
        let fill = (110.0 * 115.0 / 255.0 + 255.0 * (1.0 - 115.0 / 255.0)) as u8;
        assert_eq!(colour(index(&[fill, fill, fill, 255])), [190; 3]);
        assert_eq!(colour(index(&[100, 95, 90, 255])), [96; 3]);
        assert_eq!(colour(index(&[0, 0, 0, 255])), [0; 3]);
        assert_eq!(colour(index(&[255, 250, 252, 255])), [255; 3]);
        // A colour keeps its nearest cube entry: the viewer's red, green and a channel blue.
        assert_eq!(colour(index(&[214, 39, 40, 255])), [204, 42, 51]);
        assert_eq!(colour(index(&[44, 160, 44, 255])), [51, 170, 51]);
        assert_eq!(colour(index(&[190, 215, 235, 255])), [204, 212, 255]);
        assert_eq!(palette().len(), 3 * 256);
        assert!(index(&[128, 128, 128, 255]) < UNCHANGED);
    }
}
