//! A picture of the arm for `render_mode="rgb_array"`: the link frames'
//! origins from the forward kinematics the dynamics already walk
//! ([`Dynamics::link_poses`]), projected onto the plane the arm moves in
//! most, drawn as segments over the reference pose. Plain pixels, no
//! drawing library: an RGB byte per channel, row after row.

use arm_model::ArmModel;
use arm_model::dynamics::Dynamics;
use nalgebra::Vector3;

use crate::options::EnvError;

/// The largest picture side, pixels.
const MAX_SIDE: usize = 4096;

const BACKGROUND: [u8; 3] = [255, 255, 255];
const REFERENCE: [u8; 3] = [150, 190, 240];
const ARM: [u8; 3] = [40, 40, 40];
const JOINT: [u8; 3] = [210, 40, 40];
const BASE: [u8; 3] = [120, 120, 120];

/// The plane of the picture: two world axes (0 = x, 1 = y, 2 = z) and the
/// half-width of the world square it shows, m.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Projection {
    /// The world axis drawn left to right.
    pub right: usize,
    /// The world axis drawn bottom to top.
    pub up: usize,
    /// Half the side of the square shown, m, around the root.
    pub half_width: f64,
}

/// The arm's drawing: its model's kinematics and the plane it is drawn on.
pub struct Picture {
    dynamics: Dynamics,
    /// (parent link, child link) of every joint.
    segments: Vec<(usize, usize)>,
    /// Links with no child, and the offset of their centre of mass (the tip
    /// drawn is twice as far, in the link's frame).
    leaves: Vec<(usize, Vector3<f64>)>,
    projection: Projection,
}

impl Picture {
    /// The drawing of `model`, its plane chosen from the poses near `q0`.
    pub fn new(model: &ArmModel, q0: &[f64]) -> Self {
        let mut dynamics = Dynamics::new(model, 1.0);
        let segments = model.joints.iter().map(|j| (j.parent, j.child)).collect();
        let leaves = (0..model.links.len())
            .filter(|&l| l != model.root && !model.joints.iter().any(|j| j.parent == l))
            .map(|l| {
                let o = &model.links[l].inertial_origin;
                (l, Vector3::new(o.xyz[0], o.xyz[1], o.xyz[2]))
            })
            .collect::<Vec<_>>();
        // The plane of the largest spread over a few poses around q0.
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        let mut reach = 0.0_f64;
        let n = q0.len();
        for k in 0..=2 * n {
            let mut q = q0.to_vec();
            if k > 0 {
                q[(k - 1) / 2] += if k % 2 == 0 { 0.7 } else { -0.7 };
            }
            for p in dynamics.link_poses(&q) {
                let v = p.translation.vector;
                for a in 0..3 {
                    lo[a] = lo[a].min(v[a]);
                    hi[a] = hi[a].max(v[a]);
                }
                reach = reach.max(v.norm());
            }
        }
        let tip = leaves
            .iter()
            .map(|(_, c)| 2.0 * c.norm())
            .fold(0.0, f64::max);
        let spread = |a: usize| (hi[a] - lo[a]).max(0.0);
        let mut axes = [0, 1, 2];
        axes.sort_by(|&a, &b| spread(b).total_cmp(&spread(a)));
        let (right, up) = (axes[0].min(axes[1]), axes[0].max(axes[1]));
        // z up when z is one of the two: it is the world's up.
        let (right, up) = if right == 2 { (up, right) } else { (right, up) };
        let half_width = 1.1 * (reach + tip).max(1e-3);
        Self {
            dynamics,
            segments,
            leaves,
            projection: Projection {
                right,
                up,
                half_width,
            },
        }
    }

    /// The plane the picture is drawn on.
    pub fn projection(&self) -> Projection {
        self.projection
    }

    /// `height` rows of `width` RGB pixels: the arm at `q` (dark, red
    /// joints) over the arm at `q_d` (light).
    pub fn draw(
        &mut self,
        width: usize,
        height: usize,
        q: &[f64],
        q_d: &[f64],
    ) -> Result<Vec<u8>, EnvError> {
        for (name, side) in [("render width", width), ("render height", height)] {
            if !(16..=MAX_SIDE).contains(&side) {
                return Err(EnvError::option(
                    name,
                    side,
                    format!("must be from 16 to {MAX_SIDE} pixels"),
                ));
            }
        }
        let mut canvas = Canvas {
            px: BACKGROUND.repeat(width * height),
            width,
            height,
        };
        let thick = (width.min(height) as f64 / 80.0).max(1.5);
        let reference = self.points(q_d);
        let arm = self.points(q);
        let to_px = |p: [f64; 2]| {
            let s = width.min(height) as f64 / (2.0 * self.projection.half_width);
            [
                width as f64 / 2.0 + p[0] * s,
                height as f64 / 2.0 - p[1] * s,
            ]
        };
        canvas.disc(to_px([0.0, 0.0]), 2.0 * thick, BASE);
        for (a, b) in &reference {
            canvas.segment(to_px(*a), to_px(*b), thick, REFERENCE);
        }
        for (a, b) in &arm {
            canvas.segment(to_px(*a), to_px(*b), thick, ARM);
        }
        for (a, _) in &arm {
            canvas.disc(to_px(*a), 1.2 * thick, JOINT);
        }
        Ok(canvas.px)
    }

    /// The arm's segments at `q`, projected (m, root at 0).
    fn points(&mut self, q: &[f64]) -> Vec<([f64; 2], [f64; 2])> {
        let Projection { right, up, .. } = self.projection;
        let poses = self.dynamics.link_poses(q);
        let flat = |v: Vector3<f64>| [v[right], v[up]];
        let mut out: Vec<_> = self
            .segments
            .iter()
            .filter_map(|&(p, c)| Some((poses.get(p)?, poses.get(c)?)))
            .map(|(p, c)| (flat(p.translation.vector), flat(c.translation.vector)))
            .collect();
        for (l, com) in &self.leaves {
            if let Some(p) = poses.get(*l) {
                let tip = p.translation.vector + p.rotation.transform_vector(&(2.0 * com));
                out.push((flat(p.translation.vector), flat(tip)));
            }
        }
        out
    }
}

/// RGB pixels being drawn on.
struct Canvas {
    px: Vec<u8>,
    width: usize,
    height: usize,
}

impl Canvas {
    fn disc(&mut self, c: [f64; 2], r: f64, colour: [u8; 3]) {
        if !(c[0].is_finite() && c[1].is_finite()) {
            return;
        }
        let (x0, x1) = ((c[0] - r).floor().max(0.0), (c[0] + r).ceil());
        let (y0, y1) = ((c[1] - r).floor().max(0.0), (c[1] + r).ceil());
        let (x1, y1) = (
            x1.min(self.width as f64 - 1.0),
            y1.min(self.height as f64 - 1.0),
        );
        if x0 > x1 || y0 > y1 {
            return;
        }
        for y in y0 as usize..=y1 as usize {
            for x in x0 as usize..=x1 as usize {
                let (dx, dy) = (x as f64 - c[0], y as f64 - c[1]);
                if dx * dx + dy * dy <= r * r {
                    let i = 3 * (y * self.width + x);
                    self.px[i..i + 3].copy_from_slice(&colour);
                }
            }
        }
    }

    fn segment(&mut self, a: [f64; 2], b: [f64; 2], r: f64, colour: [u8; 3]) {
        let len = ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt();
        if !len.is_finite() {
            return;
        }
        // Discs every half radius: a solid stroke.
        let count = (2.0 * len / r).ceil().clamp(1.0, 1e5) as usize;
        for k in 0..=count {
            let t = k as f64 / count as f64;
            self.disc(
                [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])],
                r,
                colour,
            );
        }
    }
}
