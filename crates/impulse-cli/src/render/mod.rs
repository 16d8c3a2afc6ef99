//! `impulse render`: shaded previews of a scene simulated on the fly, as PNG frames and/or an
//! animated GIF, drawn on the CPU by [`raster`].
//!
//! The camera is fixed for the whole run. By default it looks at the centre of the bounding
//! box of the moving bodies at step 0 (static bodies are left out: half-spaces are infinite and
//! a ground box is usually far larger than what stands on it) from an elevated three-quarter
//! view, far enough that the box's bounding sphere fits the image. The ground is drawn as a
//! grid: the plane of an upward static half-space, or the top of a static box wider than the
//! moving bodies' box and below it, or else the bottom of the moving bodies' box.

pub mod glb;
pub mod raster;

use std::path::PathBuf;

use anyhow::{Context, Result, bail};
use clap::ValueEnum;
use image::codecs::gif::{GifEncoder, Repeat};
use image::{Delay, RgbImage, RgbaImage};
use impulse::glam::{Quat, Vec3};
use impulse::{BodyKind, Scene, ShapeDesc, World};

use crate::export::mesh::{TriMesh, shape_mesh};
use crate::export::{PALETTE, STATIC_GREY};
use raster::{Camera, Canvas, Vertex};

/// How moving bodies are coloured.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum ColourBy {
    /// By speed of the centre of mass: blue at rest, through yellow, to red at `--speed-max`.
    Speed,
    /// By island (bodies joined by a chain of touching contacts share a colour).
    Island,
    /// One palette colour per body, in scene order (the colours of the glTF/USD export).
    Body,
}

/// Options of `impulse render` beyond the scene.
#[derive(Clone, Debug)]
pub struct RenderOptions {
    /// Steps to simulate (default: the scene's).
    pub steps: Option<u32>,
    /// Draw every K-th step (step 0 and the last are always drawn).
    pub every: u32,
    /// Image size in pixels.
    pub size: (u32, u32),
    /// Directory for one PNG per drawn frame (`frame_00000.png`, numbered by step).
    pub out_dir: Option<PathBuf>,
    /// Animated GIF of the drawn frames.
    pub gif: Option<PathBuf>,
    /// Camera eye (m); default: the three-quarter view described in the module docs.
    pub eye: Option<Vec3>,
    /// Camera target (m); default: the centre of the moving bodies' box.
    pub target: Option<Vec3>,
    /// Vertical field of view (degrees).
    pub fov_deg: f32,
    /// How moving bodies are coloured.
    pub colour: ColourBy,
    /// Speed drawn in the hottest colour with `ColourBy::Speed` (m/s).
    pub speed_max: f32,
    /// Regions outlined over every frame (a goal's target box or sphere).
    pub regions: Vec<Region>,
    /// No progress bar.
    pub quiet: bool,
}

/// A region drawn as an outline over the bodies (not hidden by them), in [`REGION_COLOUR`]:
/// a box's twelve edges, a sphere's three great circles about its axes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Region {
    /// An axis-aligned box between two corners (m, world frame).
    Box { min: Vec3, max: Vec3 },
    /// A sphere (m, world frame).
    Sphere { centre: Vec3, radius: f32 },
}

/// The colour regions are outlined in (linear RGB): a magenta no body is drawn in.
pub const REGION_COLOUR: Vec3 = Vec3::new(1.0, 0.0, 1.0);

/// Parses a region: `box:X0,Y0,Z0,X1,Y1,Z1` (two opposite corners, m; each coordinate of the
/// first at most the second's) or `sphere:X,Y,Z,R` (centre and radius > 0, m).
pub fn parse_region(text: &str) -> Result<Region, String> {
    let usage = || format!("'{text}' is not a region: box:X0,Y0,Z0,X1,Y1,Z1 or sphere:X,Y,Z,R (m)");
    let (kind, values) = text.split_once(':').ok_or_else(usage)?;
    let values: Vec<f32> = values
        .split(',')
        .map(|v| v.trim().parse::<f32>())
        .collect::<Result<_, _>>()
        .map_err(|_| usage())?;
    if !values.iter().all(|v| v.is_finite()) {
        return Err(usage());
    }
    match (kind.trim(), &values[..]) {
        ("box", &[x0, y0, z0, x1, y1, z1]) => {
            let (min, max) = (Vec3::new(x0, y0, z0), Vec3::new(x1, y1, z1));
            if min.cmpgt(max).any() {
                return Err(format!(
                    "'{text}': the box's first corner must be its lowest (min before max)"
                ));
            }
            Ok(Region::Box { min, max })
        }
        ("sphere", &[x, y, z, radius]) if radius > 0.0 => Ok(Region::Sphere {
            centre: Vec3::new(x, y, z),
            radius,
        }),
        _ => Err(usage()),
    }
}

impl Region {
    /// The outline's segments (pairs of world points, m).
    fn segments(&self) -> Vec<(Vec3, Vec3)> {
        match *self {
            Region::Box { min, max } => {
                let corner = |k: usize| {
                    Vec3::new(
                        if k & 1 == 0 { min.x } else { max.x },
                        if k & 2 == 0 { min.y } else { max.y },
                        if k & 4 == 0 { min.z } else { max.z },
                    )
                };
                // The corners k and k | bit differ along one axis: an edge.
                (0..8)
                    .flat_map(|k| [1, 2, 4].map(move |bit| (k, k | bit)))
                    .filter(|(a, b)| a != b)
                    .map(|(a, b)| (corner(a), corner(b)))
                    .collect()
            }
            Region::Sphere { centre, radius } => {
                const SIDES: usize = 48;
                let point = |axis: usize, k: usize| {
                    let angle = std::f32::consts::TAU * k as f32 / SIDES as f32;
                    let (s, c) = angle.sin_cos();
                    let offset = match axis {
                        0 => Vec3::new(0.0, c, s),
                        1 => Vec3::new(c, 0.0, s),
                        _ => Vec3::new(c, s, 0.0),
                    };
                    centre + radius * offset
                };
                (0..3)
                    .flat_map(|axis| {
                        (0..SIDES).map(move |k| (point(axis, k), point(axis, (k + 1) % SIDES)))
                    })
                    .collect()
            }
        }
    }
}

/// What a render wrote.
#[derive(Debug)]
pub struct RenderSummary {
    /// Frames drawn.
    pub frames: usize,
    /// The camera used.
    pub camera: Camera,
}

/// Parses `WxH` (pixels, each 16 to 8192).
pub fn parse_size(text: &str) -> Result<(u32, u32), String> {
    let bad = || format!("'{text}' is not an image size WIDTHxHEIGHT such as 320x200");
    let (w, h) = text.split_once(['x', 'X']).ok_or_else(bad)?;
    let w: u32 = w.trim().parse().map_err(|_| bad())?;
    let h: u32 = h.trim().parse().map_err(|_| bad())?;
    for v in [w, h] {
        if !(16..=8192).contains(&v) {
            return Err(format!(
                "'{text}': width and height must be 16 to 8192 pixels"
            ));
        }
    }
    Ok((w, h))
}

/// Parses `x,y,z` (three finite numbers, metres).
pub fn parse_vec3(text: &str) -> Result<Vec3, String> {
    let values: Vec<f32> = text
        .split(',')
        .map(|v| v.trim().parse::<f32>())
        .collect::<Result<_, _>>()
        .map_err(|_| format!("'{text}' is not a point x,y,z such as 0,5,20"))?;
    match values[..] {
        [x, y, z] if values.iter().all(|v| v.is_finite()) => Ok(Vec3::new(x, y, z)),
        _ => Err(format!("'{text}' is not a point x,y,z such as 0,5,20")),
    }
}

/// Parses a vertical field of view in degrees (strictly between 1 and 170).
pub fn parse_fov(text: &str) -> Result<f32, String> {
    match text.trim().parse::<f32>() {
        Ok(v) if v > 1.0 && v < 170.0 => Ok(v),
        _ => Err(format!(
            "'{text}' is not a field of view in degrees between 1 and 170"
        )),
    }
}

/// One body as drawn: its mesh in the body frame, whether it is static, and whether it is the
/// ground the grid stands for (then it is not drawn).
struct DrawnBody {
    mesh: TriMesh,
    kind: BodyKind,
    is_ground: bool,
}

/// Where the ground grid is: its height and line spacing (m).
struct Ground {
    height: f32,
    spacing: f32,
}

/// Simulates `scene` and writes the frames `options` asks for.
pub fn render(scene: &Scene, options: &RenderOptions) -> Result<RenderSummary> {
    check_options(options)?;
    let every = options.every.max(1) as u64;
    let delay_ms = (every as f64 * scene.dt as f64 * 1e3).round().max(10.0) as u32;
    // Fail before simulating if the outputs cannot be written.
    let mut sink = FrameSink::create(options, delay_ms)?;
    let mut world = World::from_scene(scene).context("cannot build the world")?;
    let steps = options.steps.unwrap_or(scene.steps) as u64;

    let (min, max) = moving_bounds(scene, &world);
    let centre = 0.5 * (min + max);
    let radius = (0.5 * (max - min).length()).max(0.5);
    let camera = checked_camera(centre, radius, options)?;
    let (bodies, ground) = drawn_bodies(scene, &world, min, max, radius)?;
    // No ground body: the grid still shows which way is down, under everything (static
    // meshes, height fields and compounds included, so that the grid hides none of them).
    let ground = ground.unwrap_or_else(|| {
        let lowest_static = bodies
            .iter()
            .enumerate()
            .filter(|(_, b)| b.kind == BodyKind::Static)
            .flat_map(|(i, b)| {
                let pose = world.poses()[i];
                b.mesh
                    .positions
                    .iter()
                    .map(move |p| (pose.rotation * Vec3::from(*p) + pose.translation).y)
            })
            .fold(f32::INFINITY, f32::min);
        Ground {
            height: min.y.min(lowest_static),
            spacing: grid_spacing(radius),
        }
    });

    let mut frames = 0;
    let bar = crate::run::progress_bar(&scene.name, steps, options.quiet);
    for step in 0..=steps {
        if step > 0 {
            bar.inc(1);
            world
                .step()
                .with_context(|| format!("the simulation stopped at step {step}"))?;
        }
        if !(step % every == 0 || step == steps) {
            continue;
        }
        let poses: Vec<(Quat, Vec3)> = world
            .poses()
            .iter()
            .map(|p| (p.rotation, p.translation))
            .collect();
        let colours = body_colours(&world, &bodies, options);
        sink.write(
            step,
            &draw(&bodies, &poses, &colours, &ground, &camera, options),
        )?;
        frames += 1;
    }
    bar.finish_and_clear();
    sink.finish()?;
    Ok(RenderSummary { frames, camera })
}

/// Checks the options that do not depend on the scene.
fn check_options(options: &RenderOptions) -> Result<()> {
    if options.out_dir.is_none() && options.gif.is_none() {
        bail!("nothing to write: give --out DIR (PNG frames) and/or --gif FILE");
    }
    if !(options.speed_max.is_finite() && options.speed_max > 0.0) {
        bail!(
            "--speed-max {} is not a speed above 0 (m/s)",
            options.speed_max
        );
    }
    if let (Some(eye), Some(target)) = (options.eye, options.target)
        && eye.distance(target) < 1e-4
    {
        bail!("the camera eye and target are the same point ({eye}): the view has no direction");
    }
    Ok(())
}

/// The camera of `options` around a sphere of `radius` about `centre`, unless it has no
/// direction.
fn checked_camera(centre: Vec3, radius: f32, options: &RenderOptions) -> Result<Camera> {
    let camera = default_camera(centre, radius, options);
    if camera.eye.distance(camera.target) < 1e-4 {
        bail!(
            "the camera eye {} is at its target: give --camera-target or another --camera-eye",
            camera.eye
        );
    }
    Ok(camera)
}

/// The GIF file under its encoder: a write error, and the flush when the encoder is dropped
/// (which writes the GIF's trailer), are kept for [`FrameSink::finish`] to report, since the
/// encoder drops them.
struct GifFile {
    out: std::io::BufWriter<std::fs::File>,
    error: std::rc::Rc<std::cell::RefCell<Option<std::io::Error>>>,
}

impl GifFile {
    fn keep<T>(&self, result: std::io::Result<T>) -> std::io::Result<T> {
        if let Err(e) = &result {
            let mut error = self.error.borrow_mut();
            if error.is_none() {
                *error = Some(std::io::Error::new(e.kind(), e.to_string()));
            }
        }
        result
    }
}

impl std::io::Write for GifFile {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        let result = self.out.write(buf);
        self.keep(result)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        let result = self.out.flush();
        self.keep(result)
    }
}

impl Drop for GifFile {
    fn drop(&mut self) {
        let _ = std::io::Write::flush(self);
    }
}

/// Where drawn frames go: PNG files in a directory and/or one animated GIF.
struct FrameSink {
    out_dir: Option<PathBuf>,
    gif: Option<(PathBuf, GifEncoder<GifFile>)>,
    /// The first write error of the GIF file, if any.
    gif_error: std::rc::Rc<std::cell::RefCell<Option<std::io::Error>>>,
    /// GIF frame delay (ms).
    delay_ms: u32,
}

impl FrameSink {
    /// Creates the directory and the GIF file of `options`.
    fn create(options: &RenderOptions, delay_ms: u32) -> Result<Self> {
        if let Some(dir) = &options.out_dir {
            std::fs::create_dir_all(dir)
                .with_context(|| format!("cannot create the frame directory {}", dir.display()))?;
        }
        let gif_error: std::rc::Rc<std::cell::RefCell<Option<std::io::Error>>> =
            std::rc::Rc::default();
        let gif = match &options.gif {
            Some(path) => {
                let file = std::fs::File::create(path)
                    .with_context(|| format!("cannot create {}", path.display()))?;
                let file = GifFile {
                    out: std::io::BufWriter::new(file),
                    error: gif_error.clone(),
                };
                let mut encoder = GifEncoder::new_with_speed(file, 10);
                // A preview loops.
                encoder
                    .set_repeat(Repeat::Infinite)
                    .with_context(|| format!("cannot write {}", path.display()))?;
                Some((path.clone(), encoder))
            }
            None => None,
        };
        Ok(Self {
            out_dir: options.out_dir.clone(),
            gif,
            gif_error,
            delay_ms,
        })
    }

    /// Ends the GIF (its trailer) and reports any error writing it, with its path.
    fn finish(mut self) -> Result<()> {
        if let Some((path, encoder)) = self.gif.take() {
            drop(encoder);
            if let Some(e) = self.gif_error.borrow_mut().take() {
                return Err(e).with_context(|| format!("cannot write {}", path.display()));
            }
        }
        Ok(())
    }

    /// Writes `canvas` as `frame_<number>.png` and/or the GIF's next frame.
    fn write(&mut self, number: u64, canvas: &Canvas) -> Result<()> {
        let (w, h) = canvas.size();
        let rgb = canvas.to_rgb8();
        if let Some(dir) = &self.out_dir {
            let path = dir.join(format!("frame_{number:05}.png"));
            let image =
                RgbImage::from_raw(w, h, rgb.clone()).context("image buffer of the wrong size")?;
            image
                .save(&path)
                .with_context(|| format!("cannot write {}", path.display()))?;
        }
        if let Some((path, encoder)) = self.gif.as_mut() {
            let rgba: Vec<u8> = rgb
                .chunks_exact(3)
                .flat_map(|p| [p[0], p[1], p[2], 255])
                .collect();
            let image =
                RgbaImage::from_raw(w, h, rgba).context("image buffer of the wrong size")?;
            let delay = Delay::from_numer_denom_ms(self.delay_ms, 1);
            encoder
                .encode_frame(image::Frame::from_parts(image, 0, 0, delay))
                .with_context(|| format!("cannot write {}", path.display()))?;
        }
        Ok(())
    }
}

/// The box of the moving bodies' meshes at their current poses (a unit box at the origin when
/// nothing moves).
fn moving_bounds(scene: &Scene, world: &World) -> (Vec3, Vec3) {
    let mut min = Vec3::splat(f32::INFINITY);
    let mut max = Vec3::splat(f32::NEG_INFINITY);
    for (i, desc) in scene.bodies.iter().enumerate() {
        if desc.kind == BodyKind::Static {
            continue;
        }
        let Ok(mesh) = shape_mesh(&desc.shape, 1.0) else {
            continue;
        };
        let pose = world.poses()[i];
        for p in &mesh.positions {
            let w = pose.rotation * Vec3::from(*p) + pose.translation;
            min = min.min(w);
            max = max.max(w);
        }
    }
    if min.x > max.x {
        (Vec3::splat(-0.5), Vec3::splat(0.5))
    } else {
        (min, max)
    }
}

/// The camera of `options`, its missing parts from the default three-quarter view of a sphere
/// of `radius` about `centre`.
fn default_camera(centre: Vec3, radius: f32, options: &RenderOptions) -> Camera {
    let target = options.target.unwrap_or(centre);
    let eye = options.eye.unwrap_or_else(|| {
        let (w, h) = options.size;
        let half_fov_y = 0.5 * options.fov_deg.to_radians();
        let half_fov_x = (half_fov_y.tan() * w as f32 / h as f32).atan();
        let half_fov = half_fov_y.min(half_fov_x);
        // From the front (+z), a little to the right and above: the 3/4 view.
        let direction = Vec3::new(0.45, 0.5, 1.0).normalize();
        target + direction * (1.05 * radius / half_fov.sin())
    });
    Camera {
        eye,
        target,
        fov_y_deg: options.fov_deg,
    }
}

/// Grid line spacing for a scene of `radius`: 1, 2 or 5 × 10^k m, about a tenth of the radius.
fn grid_spacing(radius: f32) -> f32 {
    let raw = (radius / 8.0).max(1e-3);
    let power = 10f32.powf(raw.log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * power)
        .find(|&s| s >= raw)
        .unwrap_or(power * 10.0)
}

/// The meshes of the bodies, and the ground if one body is it (see the module docs).
fn drawn_bodies(
    scene: &Scene,
    world: &World,
    min: Vec3,
    max: Vec3,
    radius: f32,
) -> Result<(Vec<DrawnBody>, Option<Ground>)> {
    let mut ground: Option<(usize, f32)> = None;
    let mut bodies = Vec::with_capacity(scene.bodies.len());
    for (i, desc) in scene.bodies.iter().enumerate() {
        let pose = world.poses()[i];
        // A thin shape as the slab it is simulated as (a flat ground box's top is its slab's).
        let slab = desc.shape.slab();
        let top = match (&desc.kind, slab.as_ref().unwrap_or(&desc.shape)) {
            (BodyKind::Static, ShapeDesc::HalfSpace { normal }) => {
                let up = pose.rotation * Vec3::from(*normal).normalize_or_zero();
                (up.y > 0.999).then_some(pose.translation.y)
            }
            (BodyKind::Static, ShapeDesc::Cuboid { half_extents }) => {
                let upright = (pose.rotation * Vec3::Y).y > 0.999;
                let [hx, hy, hz] = *half_extents;
                let wide = hx.min(hz) >= 0.5 * (max.x - min.x).max(max.z - min.z);
                let top = pose.translation.y + hy;
                (upright && wide && top <= min.y + 0.05).then_some(top)
            }
            _ => None,
        };
        // The highest candidate is the ground the bodies stand on.
        if let Some(top) = top
            && ground.is_none_or(|(_, h)| top > h)
        {
            ground = Some((i, top));
        }
        let mesh = shape_mesh(&desc.shape, 4.0 * radius + 20.0)
            .with_context(|| format!("cannot draw body {i}"))?;
        bodies.push(DrawnBody {
            mesh,
            kind: desc.kind,
            is_ground: false,
        });
    }
    Ok(match ground {
        Some((i, height)) => {
            bodies[i].is_ground = true;
            (
                bodies,
                Some(Ground {
                    height,
                    spacing: grid_spacing(radius),
                }),
            )
        }
        None => (bodies, None),
    })
}

/// One frame: each body drawn at its pose (rotation, translation) in its colour (linear RGB),
/// all but the ground, over the ground grid; then the regions' outlines over everything.
fn draw(
    bodies: &[DrawnBody],
    poses: &[(Quat, Vec3)],
    colours: &[Vec3],
    ground: &Ground,
    camera: &Camera,
    options: &RenderOptions,
) -> Canvas {
    let (w, h) = options.size;
    let mut canvas = Canvas::new(w, h, camera);
    canvas.draw_background(Some((ground.height, ground.spacing)));
    for ((body, &(rotation, translation)), &colour) in bodies.iter().zip(poses).zip(colours) {
        if body.is_ground {
            continue;
        }
        let vertices: Vec<Vertex> = body
            .mesh
            .positions
            .iter()
            .zip(&body.mesh.normals)
            .map(|(p, n)| Vertex {
                position: rotation * Vec3::from(*p) + translation,
                normal: rotation * Vec3::from(*n),
                colour,
            })
            .collect();
        for t in body.mesh.indices.chunks_exact(3) {
            canvas.draw_triangle(
                &vertices[t[0] as usize],
                &vertices[t[1] as usize],
                &vertices[t[2] as usize],
            );
        }
    }
    for region in &options.regions {
        for (a, b) in region.segments() {
            canvas.draw_line(a, b, REGION_COLOUR);
        }
    }
    canvas
}

/// Each body's base colour (linear RGB) under `options.colour`; static bodies are grey.
fn body_colours(world: &World, bodies: &[DrawnBody], options: &RenderOptions) -> Vec<Vec3> {
    let n = bodies.len();
    let palette = |k: usize| Vec3::from(PALETTE[k % PALETTE.len()]);
    let island_root = match options.colour {
        ColourBy::Island => Some(islands(world, bodies)),
        _ => None,
    };
    let mut moving = 0;
    (0..n)
        .map(|i| {
            if bodies[i].kind == BodyKind::Static {
                return Vec3::from(STATIC_GREY);
            }
            moving += 1;
            match options.colour {
                ColourBy::Body => palette(moving - 1),
                ColourBy::Island => palette(island_root.as_ref().map_or(i, |roots| roots[i])),
                ColourBy::Speed => {
                    let v = world.linear_velocities()[i].length();
                    heat((v / options.speed_max.max(1e-6)).clamp(0.0, 1.0)) * tint(i)
                }
            }
        })
        .collect()
}

/// A brightness factor within ±8 % that depends only on the body index, so that touching bodies
/// of one colour (a pile at rest, coloured by speed) stay apart in the image.
fn tint(i: usize) -> f32 {
    let hash = (i as u32).wrapping_mul(2_654_435_761) >> 24;
    0.92 + 0.16 * hash as f32 / 255.0
}

/// Blue (0) → yellow (0.5) → red (1), linear RGB.
fn heat(s: f32) -> Vec3 {
    let cold = Vec3::new(0.12, 0.30, 0.75);
    let warm = Vec3::new(0.95, 0.78, 0.15);
    let hot = Vec3::new(0.85, 0.10, 0.06);
    if s < 0.5 {
        cold.lerp(warm, 2.0 * s)
    } else {
        warm.lerp(hot, 2.0 * s - 1.0)
    }
}

/// Per body, the smallest body index of its island: moving bodies joined by touching contacts
/// (static bodies join nothing, as in the engine's islands).
fn islands(world: &World, bodies: &[DrawnBody]) -> Vec<usize> {
    let mut parent: Vec<usize> = (0..bodies.len()).collect();
    fn find(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    for pair in world.contact_pairs() {
        if !pair.touching() {
            continue;
        }
        let (Some(a), Some(b)) = (world.body(pair.body1()), world.body(pair.body2())) else {
            continue;
        };
        let (a, b) = (a.index(), b.index());
        // Static and kinematic bodies join no island (as in the engine).
        if !bodies[a].kind.is_dynamic() || !bodies[b].kind.is_dynamic() {
            continue;
        }
        let (ra, rb) = (find(&mut parent, a), find(&mut parent, b));
        // The smaller index is the root, so an island's colour follows its first body.
        parent[ra.max(rb)] = ra.min(rb);
    }
    (0..bodies.len()).map(|i| find(&mut parent, i)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_points_and_fields_of_view_parse_or_name_the_bad_value() {
        assert_eq!(parse_size("320x200"), Ok((320, 200)));
        assert!(parse_size("320").unwrap_err().contains("'320'"));
        assert!(parse_size("0x200").unwrap_err().contains("16 to 8192"));
        assert_eq!(parse_vec3("1, 2,3"), Ok(Vec3::new(1.0, 2.0, 3.0)));
        assert!(parse_vec3("1,2").is_err());
        assert!(parse_vec3("1,2,nan").is_err());
        assert_eq!(parse_fov("40"), Ok(40.0));
        assert!(parse_fov("180").is_err());
    }

    #[test]
    fn regions_parse_or_name_the_bad_value() {
        assert_eq!(
            parse_region("box:-1,0,-1,1,0.5,1"),
            Ok(Region::Box {
                min: Vec3::new(-1.0, 0.0, -1.0),
                max: Vec3::new(1.0, 0.5, 1.0)
            })
        );
        assert_eq!(
            parse_region("sphere:0,1,0,0.25"),
            Ok(Region::Sphere {
                centre: Vec3::Y,
                radius: 0.25
            })
        );
        assert!(
            parse_region("box:1,0,0,0,1,1")
                .unwrap_err()
                .contains("lowest")
        );
        assert!(parse_region("sphere:0,1,0,-1").is_err());
        assert!(
            parse_region("cone:0,0,0,1")
                .unwrap_err()
                .contains("'cone:0,0,0,1'")
        );
        // A box is its twelve edges.
        let edges = parse_region("box:0,0,0,1,1,1").unwrap().segments();
        assert_eq!(edges.len(), 12);
        assert!(
            edges
                .iter()
                .all(|(a, b)| (a.distance(*b) - 1.0).abs() < 1e-6)
        );
    }

    #[test]
    fn grid_spacing_is_one_two_or_five_times_a_power_of_ten() {
        assert_eq!(grid_spacing(8.0), 1.0);
        assert_eq!(grid_spacing(14.0), 2.0);
        assert_eq!(grid_spacing(30.0), 5.0);
        assert!((grid_spacing(0.8) - 0.1).abs() < 1e-6);
    }
}
