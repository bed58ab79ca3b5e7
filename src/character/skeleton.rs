//! A character's node hierarchy, skin joints and animations, and the pose at
//! a time: every node's world transform from its rest transform with the
//! animated channels sampled (linear, step or cubic spline; rotations by
//! normalised linear interpolation along the shorter arc), then every joint's
//! skinning matrix (its world transform times its inverse bind matrix).

use glam::{Mat4, Quat, Vec3};

use crate::error::{Error, Result};

/// Latest (and earliest) key time an animation may have, seconds (about 11.6
/// days): a key past it is a broken file, not an animation.
pub const MAX_KEY_TIME_S: f32 = 1e6;

/// Why `q` is no rotation, if it is not: a quaternion is normalised before
/// use, so any length in 10⁻⁶..=10⁶ is taken (files store slightly
/// unnormalised ones), and one outside (zero, or so long that normalising it
/// overflows) is refused.
pub(crate) fn not_a_rotation(q: Quat) -> Option<String> {
    let length = q.as_dquat().length();
    // The bounds as the f32 values a file holds (1e-6 in f32 lies just below
    // 1e-6 in f64).
    let fine = q.is_finite() && (f64::from(1e-6f32)..=f64::from(1e6f32)).contains(&length);
    (!fine).then(|| {
        let shown = format!("[{:?}, {:?}, {:?}, {:?}]", q.x, q.y, q.z, q.w);
        format!("{shown} is not a rotation (a quaternion of length {length:.3e}, normalised to use)")
    })
}

/// A node of the hierarchy with its rest transform.
#[derive(Debug, Clone, PartialEq)]
pub struct Node {
    /// Its name ("" when unnamed).
    pub name: String,
    /// Its parent node, none for a root.
    pub parent: Option<usize>,
    /// Rest translation.
    pub translation: Vec3,
    /// Rest rotation.
    pub rotation: Quat,
    /// Rest scale.
    pub scale: Vec3,
}

/// How a channel interpolates between its keys.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Sampling {
    /// Linear (rotations: normalised linear along the shorter arc).
    Linear,
    /// The previous key's value.
    Step,
    /// Cubic Hermite spline with in and out tangents per key.
    CubicSpline,
}

/// A channel's values: one per key, or three (in tangent, value, out tangent)
/// for a cubic spline.
#[derive(Debug, Clone, PartialEq)]
pub enum Keys {
    /// Translations.
    Translation(Vec<Vec3>),
    /// Rotations (unit quaternions).
    Rotation(Vec<Quat>),
    /// Scales.
    Scale(Vec<Vec3>),
}

/// One animated property of one node.
#[derive(Debug, Clone, PartialEq)]
pub struct Channel {
    /// The node it moves.
    pub node: usize,
    /// Key times, seconds, increasing.
    pub times: Vec<f32>,
    /// The values.
    pub keys: Keys,
    /// How it interpolates.
    pub sampling: Sampling,
}

/// An animation: channels over nodes.
#[derive(Debug, Clone, PartialEq)]
pub struct Animation {
    /// Its name (or "animation N").
    pub name: String,
    /// Its channels.
    pub channels: Vec<Channel>,
}

impl Animation {
    /// The time of its last key, seconds.
    pub fn duration(&self) -> f32 {
        self.channels.iter().filter_map(|c| c.times.last().copied()).fold(0.0, f32::max)
    }
}

impl Channel {
    /// Checks times (finite, increasing, at least one) against the values.
    pub(super) fn validate(&self) -> std::result::Result<(), String> {
        let n = self.times.len();
        if n == 0 {
            return Err("no keys".into());
        }
        if self.times.iter().any(|t| !t.is_finite()) || self.times.windows(2).any(|w| w[1] < w[0]) {
            return Err("key times are not finite and increasing".into());
        }
        if let Some(t) = self.times.iter().find(|t| t.abs() > MAX_KEY_TIME_S) {
            return Err(format!("a key time of {t:?} s is beyond ±{MAX_KEY_TIME_S:?} s"));
        }
        let per_key = if self.sampling == Sampling::CubicSpline { 3 } else { 1 };
        let (values, finite) = match &self.keys {
            Keys::Translation(v) | Keys::Scale(v) => (v.len(), v.iter().all(|x| x.is_finite())),
            Keys::Rotation(q) => (q.len(), q.iter().all(|x| x.is_finite())),
        };
        if values != n * per_key {
            return Err(format!("{values} values for {n} keys"));
        }
        if !finite {
            return Err("a value is not finite".into());
        }
        if let Keys::Rotation(q) = &self.keys {
            // Cubic-spline tangents (the first and third of each key's three
            // values) may be zero or long; the values themselves are rotations.
            let mut values = q.iter().enumerate().filter(|(i, _)| per_key == 1 || i % 3 == 1);
            if let Some((i, why)) = values.find_map(|(i, &r)| not_a_rotation(r).map(|why| (i / per_key, why))) {
                return Err(format!("rotation key {i}: {why}"));
            }
        }
        Ok(())
    }

    /// The key segment at `t` (clamped to the keys) and the fraction into it.
    fn segment(&self, t: f32) -> (usize, usize, f32, f32) {
        let times = &self.times;
        let last = times.len() - 1;
        // A NaN time samples the first key.
        if t.is_nan() || t <= times[0] {
            return (0, 0, 0.0, 0.0);
        }
        if t >= times[last] {
            return (last, last, 0.0, 0.0);
        }
        let b = times.partition_point(|&k| k <= t).min(last);
        let a = b - 1;
        let span = times[b] - times[a];
        let u = if span > 0.0 { (t - times[a]) / span } else { 0.0 };
        (a, b, u, span)
    }

    /// The first time a scale channel takes a component to within 1e-4 of
    /// zero, at a key or between two (a linear segment whose ends differ in
    /// sign crosses zero where it does; a cubic one is sampled 32 times a
    /// segment); `None` for a channel of another property or one that never
    /// comes near zero.
    pub fn scale_near_zero(&self) -> Option<f32> {
        let Keys::Scale(v) = &self.keys else { return None };
        let near = |s: Vec3| s.abs().min_element() <= 1e-4;
        let key = |k: usize| if self.sampling == Sampling::CubicSpline { v[3 * k + 1] } else { v[k] };
        let mut previous: Option<(f32, Vec3)> = None;
        for (k, &t) in self.times.iter().enumerate() {
            if let (Some((t0, a)), Sampling::Linear) = (previous, self.sampling) {
                let b = key(k);
                let crossing = (0..3).filter(|&i| a[i] * b[i] < 0.0).map(|i| t0 + (t - t0) * a[i] / (a[i] - b[i]));
                if let Some(at) = crossing.reduce(f32::min) {
                    return Some(at);
                }
            }
            if let (Some((t0, _)), Sampling::CubicSpline) = (previous, self.sampling) {
                let mut last = self.sample_vec(v, t0);
                for j in 1..=32 {
                    let at = t0 + (t - t0) * j as f32 / 32.0;
                    let s = self.sample_vec(v, at);
                    if near(s) || (0..3).any(|i| s[i] * last[i] < 0.0) {
                        return Some(at);
                    }
                    last = s;
                }
            }
            if near(key(k)) {
                return Some(t);
            }
            previous = Some((t, key(k)));
        }
        None
    }

    /// Samples a vector channel.
    fn sample_vec(&self, v: &[Vec3], t: f32) -> Vec3 {
        let (a, b, u, span) = self.segment(t);
        match self.sampling {
            Sampling::Step => v[a],
            Sampling::Linear => v[a].lerp(v[b], u),
            Sampling::CubicSpline => hermite(v[3 * a + 1], v[3 * a + 2] * span, v[3 * b + 1], v[3 * b] * span, u),
        }
    }

    /// Samples a rotation channel.
    fn sample_quat(&self, q: &[Quat], t: f32) -> Quat {
        let (a, b, u, span) = self.segment(t);
        let q = match self.sampling {
            Sampling::Step => q[a],
            Sampling::Linear => {
                let end = if q[a].dot(q[b]) < 0.0 { -q[b] } else { q[b] };
                q[a].lerp(end, u)
            }
            Sampling::CubicSpline => {
                let c = |i: usize| glam::Vec4::from(q[i]);
                Quat::from_vec4(hermite4(c(3 * a + 1), c(3 * a + 2) * span, c(3 * b + 1), c(3 * b) * span, u))
            }
        };
        q.normalize()
    }
}

fn hermite(p0: Vec3, m0: Vec3, p1: Vec3, m1: Vec3, t: f32) -> Vec3 {
    let (t2, t3) = (t * t, t * t * t);
    p0 * (2.0 * t3 - 3.0 * t2 + 1.0) + m0 * (t3 - 2.0 * t2 + t) + p1 * (-2.0 * t3 + 3.0 * t2) + m1 * (t3 - t2)
}

fn hermite4(p0: glam::Vec4, m0: glam::Vec4, p1: glam::Vec4, m1: glam::Vec4, t: f32) -> glam::Vec4 {
    let (t2, t3) = (t * t, t * t * t);
    p0 * (2.0 * t3 - 3.0 * t2 + 1.0) + m0 * (t3 - 2.0 * t2 + t) + p1 * (-2.0 * t3 + 3.0 * t2) + m1 * (t3 - t2)
}

/// The hierarchy, the skin and the animations.
#[derive(Debug, Clone, PartialEq)]
pub struct Skeleton {
    /// Every node, parents before or after children (any order).
    pub nodes: Vec<Node>,
    /// The skin's joints: node indices, in the order the vertices' joint indices use.
    pub joints: Vec<usize>,
    /// Per joint, the inverse bind matrix.
    pub inverse_bind: Vec<Mat4>,
    /// The animations.
    pub animations: Vec<Animation>,
    /// Nodes ordered parents first.
    order: Vec<usize>,
}

impl Skeleton {
    /// Checks the hierarchy (no cycle, parents and channels naming nodes that exist).
    pub fn new(
        nodes: Vec<Node>,
        joints: Vec<usize>,
        inverse_bind: Vec<Mat4>,
        animations: Vec<Animation>,
    ) -> Result<Self> {
        let bad = |reason: String| Error::Malformed { format: crate::error::FileFormat::Gltf, reason };
        let n = nodes.len();
        if let Some(j) = joints.iter().find(|&&j| j >= n) {
            return Err(bad(format!("joint node {j} does not exist ({n} nodes)")));
        }
        if joints.len() != inverse_bind.len() {
            return Err(bad(format!("{} joints, {} inverse bind matrices", joints.len(), inverse_bind.len())));
        }
        for a in &animations {
            if let Some(c) = a.channels.iter().find(|c| c.node >= n) {
                return Err(bad(format!("{:?} moves node {} ({n} nodes)", a.name, c.node)));
            }
            for (k, c) in a.channels.iter().enumerate() {
                c.validate().map_err(|why| bad(format!("{:?} channel {k}: {why}", a.name)))?;
            }
        }
        // Parents first: from the roots down through each node's children.
        let mut children = vec![Vec::new(); n];
        let mut order = Vec::with_capacity(n);
        for (i, node) in nodes.iter().enumerate() {
            match node.parent {
                Some(p) if p < n => children[p].push(i),
                Some(_) => return Err(bad(format!("node {i}'s parent does not exist"))),
                None => order.push(i),
            }
        }
        let mut next = 0;
        while next < order.len() {
            order.extend_from_slice(&children[order[next]]);
            next += 1;
        }
        if order.len() != n {
            return Err(bad("the node hierarchy has a cycle".into()));
        }
        Ok(Skeleton { nodes, joints, inverse_bind, animations, order })
    }

    /// The animation named `name`, or numbered so.
    pub fn animation_index(&self, name: &str) -> Result<usize> {
        if let Some(i) = self.animations.iter().position(|a| a.name == name) {
            return Ok(i);
        }
        match name.parse::<usize>() {
            Ok(i) if i < self.animations.len() => Ok(i),
            _ => {
                let names: Vec<&str> = self.animations.iter().map(|a| a.name.as_str()).collect();
                Err(Error::param("animation", name, format!("one of {names:?} or an index below {}", names.len())))
            }
        }
    }

    /// Every node's world transform with `animation` (none: the rest pose)
    /// sampled at `time` seconds (wrapped to its duration when `looped`; a
    /// time that is not finite samples the first keys).
    pub fn node_transforms(&self, animation: Option<usize>, time: f32, looped: bool) -> Vec<Mat4> {
        let mut local: Vec<(Vec3, Quat, Vec3)> =
            self.nodes.iter().map(|n| (n.translation, n.rotation, n.scale)).collect();
        if let Some(a) = animation.and_then(|a| self.animations.get(a)) {
            let duration = a.duration();
            let t = if looped && duration > 0.0 { time.rem_euclid(duration) } else { time };
            for c in &a.channels {
                let l = &mut local[c.node];
                match &c.keys {
                    Keys::Translation(v) => l.0 = c.sample_vec(v, t),
                    Keys::Rotation(q) => l.1 = c.sample_quat(q, t),
                    Keys::Scale(v) => l.2 = c.sample_vec(v, t),
                }
            }
        }
        let mut world = vec![Mat4::IDENTITY; self.nodes.len()];
        for &i in &self.order {
            let (t, r, s) = local[i];
            let m = Mat4::from_scale_rotation_translation(s, r.normalize(), t);
            world[i] = match self.nodes[i].parent {
                Some(p) => world[p] * m,
                None => m,
            };
        }
        world
    }

    /// Per joint: world transform · inverse bind matrix, from node transforms.
    pub fn skinning(&self, world: &[Mat4]) -> Vec<Mat4> {
        self.joints.iter().zip(&self.inverse_bind).map(|(&j, ib)| world[j] * *ib).collect()
    }
}
