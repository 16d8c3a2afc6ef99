//! A small software rasteriser: a perspective camera, a procedural ground grid and
//! z-buffered, Gouraud-shaded triangles.
//!
//! Conventions: world metres, y up, right-handed (the engine's). Colours are linear RGB in
//! 0..1 until [`Canvas::to_rgb8`] encodes them as sRGB. Depth is the normalised device depth of
//! `glam::camera::rh::proj::directx::perspective` (0 at the near plane, 1 at the far plane), which is affine in
//! screen space, so it is interpolated linearly across a triangle.

use impulse::glam::{Mat4, Vec3, Vec4, Vec4Swizzles};

/// Direction towards the key light (world frame, unit length after normalisation).
const KEY_LIGHT: Vec3 = Vec3::new(0.35, 1.0, 0.55);
/// Share of a body's colour lit without regard to its orientation.
const AMBIENT: f32 = 0.28;
/// Share lit by the key light, times the cosine of the angle of incidence.
const KEY: f32 = 0.62;
/// Share lit by a fill light at the camera, so faces turned from the key light keep some shape.
const FILL: f32 = 0.18;

/// Sky colour at the horizon and at the zenith (linear RGB).
const SKY_HORIZON: Vec3 = Vec3::new(0.78, 0.84, 0.90);
const SKY_ZENITH: Vec3 = Vec3::new(0.32, 0.45, 0.66);
/// Ground colour between grid lines, and the colour of the lines (linear RGB).
const GROUND: Vec3 = Vec3::new(0.62, 0.62, 0.58);
const GRID_LINE: Vec3 = Vec3::new(0.16, 0.16, 0.16);

/// A perspective camera looking from `eye` at `target` with the world's y axis up.
#[derive(Clone, Copy, Debug)]
pub struct Camera {
    /// Eye position (m).
    pub eye: Vec3,
    /// Point at the centre of the image (m).
    pub target: Vec3,
    /// Vertical field of view (degrees).
    pub fov_y_deg: f32,
}

impl Camera {
    /// World → clip space for an image of `width` × `height` pixels. The near plane is at 1 %
    /// of the distance to the target (at least 1 cm), the far plane 100 times as far.
    pub fn view_projection(&self, width: u32, height: u32) -> Mat4 {
        let distance = (self.target - self.eye).length().max(1e-3);
        let near = (0.01 * distance).max(0.01);
        let far = 100.0 * distance + 100.0;
        // A view straight down or up has no defined roll about y: use z as up then.
        let forward = (self.target - self.eye) / distance;
        let up = if forward.y.abs() > 0.999 {
            Vec3::Z
        } else {
            Vec3::Y
        };
        // Right-handed, y up, clip z from 0 at the near plane to w at the far plane.
        let projection = impulse::glam::camera::rh::proj::directx::perspective(
            self.fov_y_deg.to_radians(),
            width as f32 / height as f32,
            near,
            far,
        );
        projection * impulse::glam::camera::rh::view::look_at_mat4(self.eye, self.target, up)
    }
}

/// A triangle's corner ready to draw: world position, unit world normal and base colour.
#[derive(Clone, Copy, Debug)]
pub struct Vertex {
    /// Position (m, world frame).
    pub position: Vec3,
    /// Unit normal (world frame).
    pub normal: Vec3,
    /// Base colour before lighting (linear RGB, 0..1).
    pub colour: Vec3,
}

/// A colour image with a depth buffer.
pub struct Canvas {
    width: u32,
    height: u32,
    colour: Vec<Vec3>,
    depth: Vec<f32>,
    view_projection: Mat4,
    inverse: Mat4,
    eye: Vec3,
}

/// A point in clip space with the colour it is drawn with.
#[derive(Clone, Copy)]
struct ClipVertex {
    clip: Vec4,
    colour: Vec3,
}

impl Canvas {
    /// A canvas of `width` × `height` pixels seen through `camera`, cleared to the sky (depth
    /// at the far plane).
    pub fn new(width: u32, height: u32, camera: &Camera) -> Self {
        let view_projection = camera.view_projection(width, height);
        let mut canvas = Self {
            width,
            height,
            colour: vec![Vec3::ZERO; (width * height) as usize],
            depth: vec![1.0; (width * height) as usize],
            view_projection,
            inverse: view_projection.inverse(),
            eye: camera.eye,
        };
        canvas.draw_background(None);
        canvas
    }

    /// Width and height in pixels.
    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// The world direction of the ray through the centre of pixel (`x`, `y`), unit length.
    fn ray(&self, x: u32, y: u32) -> Vec3 {
        let ndc_x = 2.0 * (x as f32 + 0.5) / self.width as f32 - 1.0;
        let ndc_y = 1.0 - 2.0 * (y as f32 + 0.5) / self.height as f32;
        let near = self.inverse * Vec4::new(ndc_x, ndc_y, 0.0, 1.0);
        let far = self.inverse * Vec4::new(ndc_x, ndc_y, 1.0, 1.0);
        (far.xyz() / far.w - near.xyz() / near.w).normalize_or_zero()
    }

    /// Sky everywhere, and where the ray through a pixel meets the horizontal plane
    /// y = `ground` in front of the eye, the ground with grid lines every `spacing` metres
    /// (with its depth, so bodies drawn later are hidden behind it only where they are below
    /// it). `ground` is `Some((height, spacing))` in metres.
    pub fn draw_background(&mut self, ground: Option<(f32, f32)>) {
        let pixel_angle = {
            // The angle one pixel spans at the image centre, from the projection's scale.
            let scale = self.view_projection.y_axis.y.abs().max(1e-6);
            2.0 / (scale * self.height as f32)
        };
        for y in 0..self.height {
            for x in 0..self.width {
                let direction = self.ray(x, y);
                let up = direction.y.clamp(0.0, 1.0);
                let sky = SKY_HORIZON.lerp(SKY_ZENITH, up.sqrt());
                let index = (y * self.width + x) as usize;
                self.colour[index] = sky;
                self.depth[index] = 1.0;
                let Some((height, spacing)) = ground else {
                    continue;
                };
                // The eye must be above the ground and the ray going down to meet it.
                if self.eye.y <= height || direction.y >= -1e-6 {
                    continue;
                }
                let t = (height - self.eye.y) / direction.y;
                let hit = self.eye + t * direction;
                let projected = self.view_projection * hit.extend(1.0);
                let depth = projected.z / projected.w;
                if !(0.0..1.0).contains(&depth) {
                    continue;
                }
                // A pixel covers `footprint` metres of ground along the ray's slant.
                let footprint = t * pixel_angle / direction.y.abs().max(0.05);
                let line = |c: f32| {
                    let d = (c / spacing - (c / spacing).round()).abs() * spacing;
                    (1.0 - d / (0.75 * footprint.max(1e-6))).clamp(0.0, 1.0)
                };
                let coverage = line(hit.x).max(line(hit.z));
                // Lines closer than a few pixels blur into a tone: fade them out from four
                // pixels apart to one and a half.
                let fade = ((spacing / footprint.max(1e-6) - 1.5) / 2.5).clamp(0.0, 1.0);
                let ground_colour = GROUND.lerp(GRID_LINE, coverage * fade);
                // Haze towards the horizon.
                let haze = (-(t / (400.0 * spacing))).exp();
                self.colour[index] = SKY_HORIZON.lerp(ground_colour, haze);
                self.depth[index] = depth;
            }
        }
    }

    /// Draws the triangle `a b c` (counter-clockwise seen from its front) with per-vertex
    /// lighting, if it faces the camera.
    pub fn draw_triangle(&mut self, a: &Vertex, b: &Vertex, c: &Vertex) {
        let key = KEY_LIGHT.normalize();
        let shade = |v: &Vertex| {
            let to_eye = (self.eye - v.position).normalize_or_zero();
            let light =
                AMBIENT + KEY * v.normal.dot(key).max(0.0) + FILL * v.normal.dot(to_eye).max(0.0);
            ClipVertex {
                clip: self.view_projection * v.position.extend(1.0),
                colour: v.colour * light,
            }
        };
        let polygon = clip_near([shade(a), shade(b), shade(c)]);
        for k in 1..polygon.len().saturating_sub(1) {
            self.fill(polygon[0], polygon[k], polygon[k + 1]);
        }
    }

    /// Fills a triangle whose corners are in front of the near plane.
    fn fill(&mut self, a: ClipVertex, b: ClipVertex, c: ClipVertex) {
        let (w, h) = (self.width as f32, self.height as f32);
        let screen = |v: &ClipVertex| {
            let ndc = v.clip.xyz() / v.clip.w;
            Vec3::new((ndc.x + 1.0) * 0.5 * w, (1.0 - ndc.y) * 0.5 * h, ndc.z)
        };
        let (pa, pb, pc) = (screen(&a), screen(&b), screen(&c));
        let edge =
            |p: Vec3, q: Vec3, x: f32, y: f32| (q.x - p.x) * (y - p.y) - (q.y - p.y) * (x - p.x);
        let area = edge(pa, pb, pc.x, pc.y);
        // Screen y points down, so a counter-clockwise front face has negative area here.
        if area >= 0.0 || !area.is_finite() {
            return;
        }
        let min_x = pa.x.min(pb.x).min(pc.x).floor().max(0.0) as u32;
        let max_x = pa.x.max(pb.x).max(pc.x).ceil().min(w - 1.0).max(0.0) as u32;
        let min_y = pa.y.min(pb.y).min(pc.y).floor().max(0.0) as u32;
        let max_y = pa.y.max(pb.y).max(pc.y).ceil().min(h - 1.0).max(0.0) as u32;
        for y in min_y..=max_y {
            let py = y as f32 + 0.5;
            for x in min_x..=max_x {
                let px = x as f32 + 0.5;
                let wa = edge(pb, pc, px, py) / area;
                let wb = edge(pc, pa, px, py) / area;
                let wc = edge(pa, pb, px, py) / area;
                if wa < 0.0 || wb < 0.0 || wc < 0.0 {
                    continue;
                }
                let depth = wa * pa.z + wb * pb.z + wc * pc.z;
                let index = (y * self.width + x) as usize;
                if !(0.0..self.depth[index]).contains(&depth) {
                    continue;
                }
                self.depth[index] = depth;
                self.colour[index] = wa * a.colour + wb * b.colour + wc * c.colour;
            }
        }
    }

    /// Draws the segment `a`–`b` (world, m) one pixel wide in `colour` (linear RGB, unlit) over
    /// whatever is drawn (no depth test: an outline stays seen behind a body); the part behind
    /// the near plane is cut off.
    pub fn draw_line(&mut self, a: Vec3, b: Vec3, colour: Vec3) {
        let (mut p, mut q) = (
            self.view_projection * a.extend(1.0),
            self.view_projection * b.extend(1.0),
        );
        if p.z < 0.0 && q.z < 0.0 {
            return;
        }
        if p.z < 0.0 || q.z < 0.0 {
            let s = p.z / (p.z - q.z);
            let cut = p.lerp(q, s);
            if p.z < 0.0 { p = cut } else { q = cut }
        }
        if p.w <= 0.0 || q.w <= 0.0 {
            return;
        }
        let (w, h) = (self.width as f32, self.height as f32);
        let screen = |v: Vec4| {
            let ndc = v.xyz() / v.w;
            ((ndc.x + 1.0) * 0.5 * w, (1.0 - ndc.y) * 0.5 * h)
        };
        let ((x0, y0), (x1, y1)) = (screen(p), screen(q));
        // One sample per pixel along the longer screen axis (capped: a segment reaching far
        // off screen is not walked pixel by pixel).
        let samples = (x1 - x0)
            .abs()
            .max((y1 - y0).abs())
            .ceil()
            .clamp(1.0, 16_384.0) as u32;
        for k in 0..=samples {
            let t = k as f32 / samples as f32;
            let (x, y) = (x0 + t * (x1 - x0), y0 + t * (y1 - y0));
            if x >= 0.0 && y >= 0.0 && x < w && y < h {
                let index = (y as u32 * self.width + x as u32) as usize;
                self.colour[index] = colour;
            }
        }
    }

    /// The image as 8-bit sRGB, row by row from the top left.
    pub fn to_rgb8(&self) -> Vec<u8> {
        let encode = |c: f32| {
            let c = c.clamp(0.0, 1.0);
            let s = if c <= 0.003_130_8 {
                12.92 * c
            } else {
                1.055 * c.powf(1.0 / 2.4) - 0.055
            };
            (s * 255.0 + 0.5) as u8
        };
        self.colour
            .iter()
            .flat_map(|c| [encode(c.x), encode(c.y), encode(c.z)])
            .collect()
    }
}

/// The part of a triangle in front of the near plane (clip z ≥ 0), as a
/// convex polygon of up to four corners (Sutherland–Hodgman against one plane).
fn clip_near(triangle: [ClipVertex; 3]) -> Vec<ClipVertex> {
    let inside = |v: &ClipVertex| v.clip.z >= 0.0 && v.clip.w > 0.0;
    if triangle.iter().all(inside) {
        return triangle.to_vec();
    }
    let mut out = Vec::with_capacity(4);
    for k in 0..3 {
        let (p, q) = (triangle[k], triangle[(k + 1) % 3]);
        if p.clip.z >= 0.0 {
            out.push(p);
        }
        if (p.clip.z >= 0.0) != (q.clip.z >= 0.0) {
            let s = p.clip.z / (p.clip.z - q.clip.z);
            out.push(ClipVertex {
                clip: p.clip.lerp(q.clip, s),
                colour: p.colour.lerp(q.colour, s),
            });
        }
    }
    out.retain(|v| v.clip.w > 0.0);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera() -> Camera {
        Camera {
            eye: Vec3::new(0.0, 2.0, 10.0),
            target: Vec3::ZERO,
            fov_y_deg: 40.0,
        }
    }

    #[test]
    fn the_target_projects_to_the_image_centre() {
        let m = camera().view_projection(320, 200);
        let p = m * Vec4::new(0.0, 0.0, 0.0, 1.0);
        assert!((p.x / p.w).abs() < 1e-5 && (p.y / p.w).abs() < 1e-5);
        assert!((0.0..1.0).contains(&(p.z / p.w)));
    }

    #[test]
    fn a_front_facing_triangle_is_drawn_and_a_back_facing_one_is_not() {
        let v = |x: f32, y: f32| Vertex {
            position: Vec3::new(x, y, 0.0),
            normal: Vec3::Z,
            colour: Vec3::new(1.0, 0.0, 0.0),
        };
        let mut canvas = Canvas::new(64, 64, &camera());
        canvas.draw_triangle(&v(-1.0, -1.0), &v(1.0, -1.0), &v(0.0, 1.0));
        let red = canvas
            .colour
            .iter()
            .filter(|c| c.x > 0.5 && c.z < 0.1)
            .count();
        assert!(red > 50, "{red} red pixels");
        let mut canvas = Canvas::new(64, 64, &camera());
        canvas.draw_triangle(&v(-1.0, -1.0), &v(0.0, 1.0), &v(1.0, -1.0));
        let red = canvas
            .colour
            .iter()
            .filter(|c| c.x > 0.5 && c.z < 0.1)
            .count();
        assert_eq!(red, 0);
    }
}
