//! Mechanisms in maximal coordinates: point masses and rigid bodies, each a component of a
//! modular interconnection, held together by joints.
//!
//! - trep's n-link chain: `n` unit point masses on massless unit rods from a pivot, in the
//!   vertical plane (`point_chain`); the same model as `chain::Chain` in reduced coordinates
//!   (absolute angles), and as `PointChain2`, one model with its rods as holonomic constraints.
//! - A chain of rigid rods in space hanging from ball joints (`body_chain`).
//! - A four-bar linkage in the plane, a closed loop of three bars pinned to each other and to
//!   the ground (`four_bar`), and a slider-crank (`slider_crank`).
//! - A humanoid-like tree of nine bodies on ball joints, free in space (`HUMANOID`, `tree`).
//!
//! The tour's rows (`reports`) check each against one model with its joints as holonomic
//! constraints or against its conserved momenta.

use std::time::Instant;

use dirac::nalgebra::{Matrix2, Rotation3, Vector2};
use dirac::prelude::*;

use super::Report;

/// A point mass `m` in the vertical plane under gravity `g` along `−y`.
#[dirac_system(
    coordinates(x, y),
    lagrangian = 0.5 * m * (dot(x).powi(2) + dot(y).powi(2)) - m * g * y,
)]
#[derive(Debug, Clone, Copy)]
pub struct PlanarMass {
    pub m: f64,
    pub g: f64,
}

/// Two point masses on rods of length `l` from the origin, one model with its rods as
/// holonomic constraints (the monolithic step's equations of `point_chain(2, …)`).
#[dirac_system(
    coordinates(x1, y1, x2, y2),
    lagrangian = 0.5 * m * (dot(x1).powi(2) + dot(y1).powi(2) + dot(x2).powi(2) + dot(y2).powi(2))
        - m * g * (y1 + y2),
    holonomic(x1 * x1 + y1 * y1 - l * l, (x2 - x1).powi(2) + (y2 - y1).powi(2) - l * l),
)]
#[derive(Debug, Clone, Copy)]
pub struct PointChain2 {
    pub m: f64,
    pub l: f64,
    pub g: f64,
}

/// A rigid bar in the vertical plane: centre `(x, y)`, angle `theta`, mass `m`, moment of
/// inertia `i` about its centre, gravity `g` along `−y`.
#[dirac_system(
    coordinates(x, y, theta),
    lagrangian = 0.5 * m * (dot(x).powi(2) + dot(y).powi(2)) + 0.5 * i * dot(theta).powi(2)
        - m * g * y,
)]
#[derive(Debug, Clone, Copy)]
pub struct PlanarBar {
    pub m: f64,
    pub i: f64,
    pub g: f64,
}

/// A rigid body in space: centre of mass `(x, y, z)`, attitude `R`, mass `m`, inertia `j` about
/// its centre in its axes, gravity `g` along `−z`.
#[dirac_system(
    coordinates(x, y, z, R: SO3),
    lagrangian = 0.5 * m * (dot(x).powi(2) + dot(y).powi(2) + dot(z).powi(2))
        + 0.5 * dot(omega(R), j * omega(R))
        - m * g * z,
)]
#[derive(Debug, Clone, Copy)]
pub struct Body {
    pub m: f64,
    pub j: [[f64; 3]; 3],
    pub g: f64,
}

/// The name of mass or body `k`.
pub fn link(k: usize) -> String {
    format!("link{k}")
}

/// trep's n-link chain in maximal coordinates: `n` masses `m` (`link0`, `link1`, …) on rods of
/// length `l`, the first from a pivot at the origin, gravity `g`, stepped by the midpoint rule
/// with step `h`.
pub fn point_chain(n: usize, m: f64, l: f64, g: f64, h: f64) -> Result<Modular, DiracError> {
    let mut chain = Modular::new(Quadrature::midpoint(), h)?;
    for k in 0..n {
        chain.add(&link(k), PlanarMass { m, g })?;
    }
    let mut above = Anchor::fixed([0.0, 0.0]);
    for k in 0..n {
        let name = link(k);
        let here = Anchor::point(&name, ["x", "y"]);
        chain.connect(Joint::rod(&format!("rod{k}"), above, here.clone(), l))?;
        above = here;
    }
    Ok(chain)
}

/// The positions and velocities (in the order of `point_chain`'s) of the chain at absolute
/// angles `theta` from the downward vertical with rates `omega` (`chain::Chain`'s coordinates).
pub fn point_chain_state(theta: &[f64], omega: &[f64], l: f64) -> (Vec<f64>, Vec<f64>) {
    let (mut q, mut v) = (Vec::new(), Vec::new());
    let (mut x, mut y, mut vx, mut vy) = (0.0, 0.0, 0.0, 0.0);
    for (t, w) in theta.iter().zip(omega) {
        let (s, c) = t.sin_cos();
        x += l * s;
        y -= l * c;
        vx += l * c * w;
        vy += l * s * w;
        q.extend([x, y]);
        v.extend([vx, vy]);
    }
    (q, v)
}

/// The absolute angles from the downward vertical of the chain at positions `q`.
pub fn point_chain_angles(q: &[f64]) -> Vec<f64> {
    let (mut x, mut y) = (0.0, 0.0);
    q.chunks(2)
        .map(|p| {
            let angle = (p[0] - x).atan2(y - p[1]);
            (x, y) = (p[0], p[1]);
            angle
        })
        .collect()
}

/// A uniform thin rod of mass `m` and length `l` along its third axis, its axial moment a tenth
/// of the others (a rod of finite thickness).
pub fn rod_body(m: f64, l: f64, g: f64) -> Body {
    let across = m * l * l / 12.0;
    Body {
        m,
        j: [
            [across, 0.0, 0.0],
            [0.0, across, 0.0],
            [0.0, 0.0, across / 10.0],
        ],
        g,
    }
}

/// `n` rods (`rod_body(m, l, g)`, `link0`, …) in space, each hanging by a ball joint at its top
/// end (`(0, 0, l/2)` in its axes) from the bottom end of the one before, the first from the
/// origin; stepped by the midpoint rule (Cayley chart) with step `h`.
pub fn body_chain(n: usize, m: f64, l: f64, g: f64, h: f64) -> Result<Modular, DiracError> {
    let mut chain = Modular::new(Quadrature::midpoint(), h)?;
    for k in 0..n {
        chain.add_on_space(&link(k), rod_body(m, l, g), Product::cayley())?;
    }
    let (top, bottom) = ([0.0, 0.0, l / 2.0], [0.0, 0.0, -l / 2.0]);
    let mut above = Anchor::fixed([0.0, 0.0, 0.0]);
    for k in 0..n {
        let name = link(k);
        let end = |offset| Anchor::body(&name, ["x", "y", "z"], "R", offset);
        chain.connect(Joint::spherical(&format!("ball{k}"), above, end(top)))?;
        above = end(bottom);
    }
    Ok(chain)
}

/// The positions and velocities (in the order of `body_chain`'s) of rods of length `l` with
/// attitudes `attitudes` turning at the body angular velocities `omegas`, hanging from the
/// origin.
pub fn body_chain_state(
    attitudes: &[Matrix3<f64>],
    omegas: &[Vector3<f64>],
    l: f64,
) -> (Vec<f64>, Vec<f64>) {
    let (mut q, mut v) = (Vec::new(), Vec::new());
    let (mut pivot, mut moving) = (Vector3::zeros(), Vector3::zeros());
    let half = Vector3::new(0.0, 0.0, -l / 2.0);
    for (r, w) in attitudes.iter().zip(omegas) {
        let centre = pivot + r * half;
        let velocity = moving + r * w.cross(&half);
        q.extend(centre.iter());
        q.extend(r.transpose().iter());
        v.extend(velocity.iter());
        v.extend(w.iter());
        pivot += r * (half * 2.0);
        moving += r * w.cross(&(half * 2.0));
    }
    (q, v)
}

/// The spatial angular momentum about the origin of a `body_chain` with positions `q` and
/// momenta `p` (each body's `x × p_x + R π`, `π` its body angular momentum).
pub fn body_chain_momentum(q: &[f64], p: &[f64]) -> Vector3<f64> {
    let mut total = Vector3::zeros();
    for (q, p) in q.chunks(12).zip(p.chunks(6)) {
        let x = Vector3::new(q[0], q[1], q[2]);
        let r = Matrix3::from_row_slice(&q[3..12]);
        total += x.cross(&Vector3::new(p[0], p[1], p[2])) + r * Vector3::new(p[3], p[4], p[5]);
    }
    total
}

/// `body_chain`'s rods hinged instead about axes along their first body axes (the first about
/// the space's `x` axis at the origin): a chain that moves in the `y`–`z` plane.
pub fn hinge_chain(n: usize, m: f64, l: f64, g: f64, h: f64) -> Result<Modular, DiracError> {
    let mut chain = Modular::new(Quadrature::midpoint(), h)?;
    for k in 0..n {
        chain.add_on_space(&link(k), rod_body(m, l, g), Product::cayley())?;
    }
    let (top, bottom, x) = ([0.0, 0.0, l / 2.0], [0.0, 0.0, -l / 2.0], [1.0, 0.0, 0.0]);
    let mut above = Anchor::fixed([0.0, 0.0, 0.0]);
    for k in 0..n {
        let name = link(k);
        let end = |offset| Anchor::body(&name, ["x", "y", "z"], "R", offset);
        chain.connect(Joint::revolute(&format!("hinge{k}"), above, end(top), x, x))?;
        above = end(bottom);
    }
    Ok(chain)
}

/// The plane's version of `hinge_chain`: bars (`PlanarBar`, mass `m`, length `l`, moment
/// `m l²/12`) pinned end to end from the origin, `(x, y)` of the plane the `(y, z)` of space.
pub fn bar_chain(n: usize, m: f64, l: f64, g: f64, h: f64) -> Result<Modular, DiracError> {
    let mut chain = Modular::new(Quadrature::midpoint(), h)?;
    let bar = PlanarBar {
        m,
        i: m * l * l / 12.0,
        g,
    };
    for k in 0..n {
        chain.add(&link(k), bar)?;
    }
    let mut above = Anchor::fixed([0.0, 0.0]);
    for k in 0..n {
        let name = link(k);
        let end = |sign: f64| Anchor::planar(&name, ["x", "y"], "theta", [sign * l / 2.0, 0.0]);
        chain.connect(Joint::spherical(&format!("pin{k}"), above, end(1.0)))?;
        above = end(-1.0);
    }
    Ok(chain)
}

/// `bar_chain`'s positions and velocities with its bars turned by `alpha` about the space's
/// `x` axis from hanging (as `hinge_chain`'s rods turned by `Rot_x(alpha)`) at rates `rates`.
pub fn bar_chain_state(alpha: &[f64], rates: &[f64], l: f64) -> (Vec<f64>, Vec<f64>) {
    let (mut q, mut v) = (Vec::new(), Vec::new());
    let (mut pivot, mut moving) = (Vector2::zeros(), Vector2::zeros());
    for (a, w) in alpha.iter().zip(rates) {
        // From the centre to the top: Rot_x(α) e_z = (−sin α, cos α) in the plane.
        let theta = a + std::f64::consts::FRAC_PI_2;
        let up = Vector2::new(theta.cos(), theta.sin());
        let turning = Vector2::new(-theta.sin(), theta.cos()) * *w;
        let centre = pivot - up * (l / 2.0);
        let velocity = moving - turning * (l / 2.0);
        q.extend([centre[0], centre[1], theta]);
        v.extend([velocity[0], velocity[1], *w]);
        pivot -= up * l;
        moving -= turning * l;
    }
    (q, v)
}

/// A body of a tree: its parent (`None`: the root), the joint's point in the parent's axes and
/// in its own, its mass and inertia about its centre.
#[derive(Debug, Clone, Copy)]
pub struct Limb {
    pub name: &'static str,
    pub parent: Option<usize>,
    pub at_parent: [f64; 3],
    pub at_self: [f64; 3],
    pub m: f64,
    pub j: [f64; 3],
}

/// A humanoid-like tree of nine bodies joined by ball joints: a torso, two arms and two legs of
/// two segments each, in the body axes of a figure standing along `z`.
pub const HUMANOID: [Limb; 9] = [
    Limb {
        name: "torso",
        parent: None,
        at_parent: [0.0; 3],
        at_self: [0.0; 3],
        m: 30.0,
        j: [1.2, 1.0, 0.4],
    },
    Limb {
        name: "upper_arm_left",
        parent: Some(0),
        at_parent: [0.0, 0.25, 0.3],
        at_self: [0.0, 0.0, 0.15],
        m: 2.0,
        j: [0.015, 0.015, 0.002],
    },
    Limb {
        name: "forearm_left",
        parent: Some(1),
        at_parent: [0.0, 0.0, -0.15],
        at_self: [0.0, 0.0, 0.13],
        m: 1.5,
        j: [0.009, 0.009, 0.001],
    },
    Limb {
        name: "upper_arm_right",
        parent: Some(0),
        at_parent: [0.0, -0.25, 0.3],
        at_self: [0.0, 0.0, 0.15],
        m: 2.0,
        j: [0.015, 0.015, 0.002],
    },
    Limb {
        name: "forearm_right",
        parent: Some(3),
        at_parent: [0.0, 0.0, -0.15],
        at_self: [0.0, 0.0, 0.13],
        m: 1.5,
        j: [0.009, 0.009, 0.001],
    },
    Limb {
        name: "thigh_left",
        parent: Some(0),
        at_parent: [0.0, 0.12, -0.35],
        at_self: [0.0, 0.0, 0.22],
        m: 8.0,
        j: [0.13, 0.13, 0.03],
    },
    Limb {
        name: "shin_left",
        parent: Some(5),
        at_parent: [0.0, 0.0, -0.22],
        at_self: [0.0, 0.0, 0.22],
        m: 4.0,
        j: [0.06, 0.06, 0.008],
    },
    Limb {
        name: "thigh_right",
        parent: Some(0),
        at_parent: [0.0, -0.12, -0.35],
        at_self: [0.0, 0.0, 0.22],
        m: 8.0,
        j: [0.13, 0.13, 0.03],
    },
    Limb {
        name: "shin_right",
        parent: Some(7),
        at_parent: [0.0, 0.0, -0.22],
        at_self: [0.0, 0.0, 0.22],
        m: 4.0,
        j: [0.06, 0.06, 0.008],
    },
];

/// The tree `limbs` as bodies (gravity `g`) joined by ball joints, free in space (its root is
/// held by nothing); the midpoint rule (Cayley chart) with step `h`.
pub fn tree(limbs: &[Limb], g: f64, h: f64) -> Result<Modular, DiracError> {
    let mut tree = Modular::new(Quadrature::midpoint(), h)?;
    for limb in limbs {
        let [a, b, c] = limb.j;
        let j = [[a, 0.0, 0.0], [0.0, b, 0.0], [0.0, 0.0, c]];
        tree.add_on_space(limb.name, Body { m: limb.m, j, g }, Product::cayley())?;
    }
    for limb in limbs {
        let Some(parent) = limb.parent else { continue };
        let end = |name: &str, offset| Anchor::body(name, ["x", "y", "z"], "R", offset);
        let joint = Joint::spherical(
            limb.name,
            end(limbs[parent].name, limb.at_parent),
            end(limb.name, limb.at_self),
        );
        tree.connect(joint)?;
    }
    Ok(tree)
}

/// The tree's positions and velocities (in `tree`'s order) with attitudes `attitudes`, body
/// angular velocities `omegas`, the root's centre at `root` moving at `velocity`: each child
/// placed and moved so that its joint's two points coincide and move alike.
pub fn tree_state(
    limbs: &[Limb],
    attitudes: &[Matrix3<f64>],
    omegas: &[Vector3<f64>],
    (root, velocity): (Vector3<f64>, Vector3<f64>),
) -> (Vec<f64>, Vec<f64>) {
    let mut centres: Vec<(Vector3<f64>, Vector3<f64>)> = Vec::new();
    for (k, limb) in limbs.iter().enumerate() {
        let (r, w) = (attitudes[k], omegas[k]);
        let placed = match limb.parent {
            None => (root, velocity),
            Some(p) => {
                let (rp, wp) = (attitudes[p], omegas[p]);
                let (a, b) = (Vector3::from(limb.at_parent), Vector3::from(limb.at_self));
                let (cp, vp) = centres[p];
                let joint = cp + rp * a;
                let moving = vp + rp * wp.cross(&a);
                (joint - r * b, moving - r * w.cross(&b))
            }
        };
        centres.push(placed);
    }
    let (mut q, mut v) = (Vec::new(), Vec::new());
    for (k, (centre, moving)) in centres.iter().enumerate() {
        q.extend(centre.iter());
        q.extend(attitudes[k].transpose().iter());
        v.extend(moving.iter());
        v.extend(omegas[k].iter());
    }
    (q, v)
}

/// The total linear momentum of bodies at positions `q` with momenta `p` (each `x, R`;
/// `p_x, π`), and their angular momentum about the origin.
pub fn bodies_momenta(q: &[f64], p: &[f64]) -> (Vector3<f64>, Vector3<f64>) {
    let mut linear = Vector3::zeros();
    for p in p.chunks(6) {
        linear += Vector3::new(p[0], p[1], p[2]);
    }
    (linear, body_chain_momentum(q, p))
}

/// A four-bar linkage's bar lengths: crank, coupler, rocker, and the ground between the pivots.
pub const FOUR_BAR: [f64; 4] = [1.0, 2.5, 2.0, 2.2];

/// The four-bar linkage in the vertical plane: the crank (`crank`) pinned to the ground at the
/// origin, the rocker (`rocker`) at `(d, 0)`, the coupler (`coupler`) pinned to both; bars of
/// `FOUR_BAR`'s lengths, unit mass per length, their joints at their ends (`(±len/2, 0)` in
/// their axes); gravity `g`; the midpoint rule with step `h`.
pub fn four_bar(g: f64, h: f64) -> Result<Modular, DiracError> {
    let [a, b, c, d] = FOUR_BAR;
    let mut linkage = Modular::new(Quadrature::midpoint(), h)?;
    for (name, len) in [("crank", a), ("coupler", b), ("rocker", c)] {
        let bar = PlanarBar {
            m: len,
            i: len * len * len / 12.0,
            g,
        };
        linkage.add(name, bar)?;
    }
    let end = |name: &str, len: f64, sign: f64| {
        Anchor::planar(name, ["x", "y"], "theta", [sign * len / 2.0, 0.0])
    };
    let pins = [
        (
            "ground_crank",
            Anchor::fixed([0.0, 0.0]),
            end("crank", a, -1.0),
        ),
        (
            "crank_coupler",
            end("crank", a, 1.0),
            end("coupler", b, -1.0),
        ),
        (
            "coupler_rocker",
            end("coupler", b, 1.0),
            end("rocker", c, 1.0),
        ),
        (
            "rocker_ground",
            end("rocker", c, -1.0),
            Anchor::fixed([d, 0.0]),
        ),
    ];
    for (name, first, second) in pins {
        linkage.connect(Joint::spherical(name, first, second))?;
    }
    Ok(linkage)
}

/// The four-bar's positions and velocities (in `four_bar`'s order) with the crank at angle
/// `phi` turning at `omega`: the coupler and rocker placed by closing the loop (the rocker's
/// tip above the ground line), their rates solved from the loop's velocity equations.
pub fn four_bar_state(phi: f64, omega: f64) -> (Vec<f64>, Vec<f64>) {
    let [a, b, c, d] = FOUR_BAR;
    // The crank's tip, and the rocker's tip at distance b from it and c from (d, 0).
    let tip = Vector2::new(a * phi.cos(), a * phi.sin());
    let pivot = Vector2::new(d, 0.0);
    let between = pivot - tip;
    let e = between.norm();
    let along = (b * b - c * c + e * e) / (2.0 * e);
    let across = (b * b - along * along).sqrt();
    let unit = between / e;
    let normal = Vector2::new(-unit[1], unit[0]);
    let joint = tip + unit * along + normal * across;
    let coupler = (joint - tip).y.atan2((joint - tip).x);
    // The rocker points from its tip (its +end) to the ground pivot (its −end).
    let rocker = (joint - pivot).y.atan2((joint - pivot).x);
    // Loop closure's rates: a ω e(φ)⊥ + b β̇ e(β)⊥ = c γ̇ e(γ)⊥.
    let perp = |t: f64| Vector2::new(-t.sin(), t.cos());
    let m = Matrix2::from_columns(&[perp(coupler) * b, -perp(rocker) * c]);
    let rates = m
        .try_inverse()
        .expect("a four-bar away from its dead points")
        * (-perp(phi) * (a * omega));
    let (beta, gamma) = (rates[0], rates[1]);
    let centre =
        |from: Vector2<f64>, t: f64, len: f64| from + Vector2::new(t.cos(), t.sin()) * (len / 2.0);
    let moving = |from: Vector2<f64>, t: f64, w: f64, len: f64| from + perp(t) * (w * len / 2.0);
    let crank_velocity = perp(phi) * (a * omega);
    let q = [
        (centre(Vector2::zeros(), phi, a), phi),
        (centre(tip, coupler, b), coupler),
        (centre(pivot, rocker, c), rocker),
    ];
    let v = [
        (moving(Vector2::zeros(), phi, omega, a), omega),
        (moving(crank_velocity, coupler, beta, b), beta),
        (moving(Vector2::zeros(), rocker, gamma, c), gamma),
    ];
    let flat = |s: [(Vector2<f64>, f64); 3]| s.iter().flat_map(|(p, t)| [p[0], p[1], *t]).collect();
    (flat(q), flat(v))
}

/// The four-bar as one model on `R⁹` with its four pins as eight holonomic constraints (the
/// monolithic step's equations of `four_bar`): bars `a`, `b`, `c` of unit mass per length,
/// ground pivots `d` apart.
#[dirac_system(
    coordinates(x1, y1, t1, x2, y2, t2, x3, y3, t3),
    lagrangian = 0.5 * a * (dot(x1).powi(2) + dot(y1).powi(2)) + a.powi(3) / 24.0 * dot(t1).powi(2)
        + 0.5 * b * (dot(x2).powi(2) + dot(y2).powi(2)) + b.powi(3) / 24.0 * dot(t2).powi(2)
        + 0.5 * c * (dot(x3).powi(2) + dot(y3).powi(2)) + c.powi(3) / 24.0 * dot(t3).powi(2)
        - g * (a * y1 + b * y2 + c * y3),
    holonomic(
        x1 - 0.5 * a * cos(t1),
        y1 - 0.5 * a * sin(t1),
        x1 + 0.5 * a * cos(t1) - x2 + 0.5 * b * cos(t2),
        y1 + 0.5 * a * sin(t1) - y2 + 0.5 * b * sin(t2),
        x2 + 0.5 * b * cos(t2) - x3 - 0.5 * c * cos(t3),
        y2 + 0.5 * b * sin(t2) - y3 - 0.5 * c * sin(t3),
        x3 - 0.5 * c * cos(t3) - d,
        y3 - 0.5 * c * sin(t3),
    ),
)]
#[derive(Debug, Clone, Copy)]
pub struct FourBarMonolithic {
    pub a: f64,
    pub b: f64,
    pub c: f64,
    pub d: f64,
    pub g: f64,
}

/// A slider-crank's lengths: the crank and the connecting rod.
pub const SLIDER_CRANK: [f64; 2] = [1.0, 3.0];

/// A slider-crank in the vertical plane: the crank (`crank`) pinned to the ground at the
/// origin, the connecting rod (`rod`) pinned to its tip, the slider (`slider`, a block of mass 1
/// and moment 0.1) pinned to the rod's other end and sliding on the ground's `x` axis (a
/// prismatic joint); bars of unit mass per length, gravity `g`, the midpoint rule with step `h`.
pub fn slider_crank(g: f64, h: f64) -> Result<Modular, DiracError> {
    let [a, b] = SLIDER_CRANK;
    let mut mechanism = Modular::new(Quadrature::midpoint(), h)?;
    for (name, len) in [("crank", a), ("rod", b)] {
        let i = len * len * len / 12.0;
        mechanism.add(name, PlanarBar { m: len, i, g })?;
    }
    let block = PlanarBar { m: 1.0, i: 0.1, g };
    mechanism.add("slider", block)?;
    let end = |name: &str, offset: f64| Anchor::planar(name, ["x", "y"], "theta", [offset, 0.0]);
    let ground = Anchor::fixed([0.0, 0.0]);
    mechanism.connect(Joint::spherical(
        "pivot",
        ground.clone(),
        end("crank", -a / 2.0),
    ))?;
    mechanism.connect(Joint::spherical(
        "wrist",
        end("crank", a / 2.0),
        end("rod", -b / 2.0),
    ))?;
    mechanism.connect(Joint::spherical(
        "pin",
        end("rod", b / 2.0),
        end("slider", 0.0),
    ))?;
    mechanism.connect(Joint::prismatic(
        "rail",
        ground,
        end("slider", 0.0),
        [1.0, 0.0],
    ))?;
    Ok(mechanism)
}

/// The slider-crank's positions and velocities (in `slider_crank`'s order) with the crank at
/// angle `phi` turning at `omega`.
pub fn slider_crank_state(phi: f64, omega: f64) -> (Vec<f64>, Vec<f64>) {
    let [a, b] = SLIDER_CRANK;
    let perp = |t: f64| Vector2::new(-t.sin(), t.cos());
    let tip = Vector2::new(a * phi.cos(), a * phi.sin());
    let x = tip[0] + (b * b - tip[1] * tip[1]).sqrt();
    let beta = (-tip[1]).atan2(x - tip[0]);
    // b β̇ e(β)⊥ − ẋ e_x = −a ω e(φ)⊥.
    let m = Matrix2::from_columns(&[perp(beta) * b, Vector2::new(-1.0, 0.0)]);
    let rates = m.try_inverse().expect("away from the dead points") * (-perp(phi) * (a * omega));
    let (beta_rate, slide) = (rates[0], rates[1]);
    let tip_velocity = perp(phi) * (a * omega);
    let along = |t: f64| Vector2::new(t.cos(), t.sin());
    let crank = along(phi) * (a / 2.0);
    let rod = tip + along(beta) * (b / 2.0);
    let q = vec![crank[0], crank[1], phi, rod[0], rod[1], beta, x, 0.0, 0.0];
    let rod_velocity = tip_velocity + perp(beta) * (beta_rate * b / 2.0);
    let crank_velocity = perp(phi) * (omega * a / 2.0);
    let v = vec![
        crank_velocity[0],
        crank_velocity[1],
        omega,
        rod_velocity[0],
        rod_velocity[1],
        beta_rate,
        slide,
        0.0,
        0.0,
    ];
    (q, v)
}

/// The slider-crank as one model on `R⁹` with its three pins and its rail as eight holonomic
/// constraints (the monolithic step's equations of `slider_crank`).
#[dirac_system(
    coordinates(x1, y1, t1, x2, y2, t2, x3, y3, t3),
    lagrangian = 0.5 * a * (dot(x1).powi(2) + dot(y1).powi(2)) + a.powi(3) / 24.0 * dot(t1).powi(2)
        + 0.5 * b * (dot(x2).powi(2) + dot(y2).powi(2)) + b.powi(3) / 24.0 * dot(t2).powi(2)
        + 0.5 * (dot(x3).powi(2) + dot(y3).powi(2)) + 0.05 * dot(t3).powi(2)
        - g * (a * y1 + b * y2 + y3),
    holonomic(
        x1 - 0.5 * a * cos(t1),
        y1 - 0.5 * a * sin(t1),
        x1 + 0.5 * a * cos(t1) - x2 + 0.5 * b * cos(t2),
        y1 + 0.5 * a * sin(t1) - y2 + 0.5 * b * sin(t2),
        x2 + 0.5 * b * cos(t2) - x3,
        y2 + 0.5 * b * sin(t2) - y3,
        t3,
        y3,
    ),
)]
#[derive(Debug, Clone, Copy)]
pub struct SliderCrankMonolithic {
    pub a: f64,
    pub b: f64,
    pub g: f64,
}

/// The four-bar's energy at positions `q` and velocities `v` (`four_bar(g, …)`'s order).
pub fn four_bar_energy(q: &[f64], v: &[f64], g: f64) -> f64 {
    let lengths = [FOUR_BAR[0], FOUR_BAR[1], FOUR_BAR[2]];
    lengths
        .iter()
        .enumerate()
        .map(|(k, len)| {
            let (m, i) = (*len, len * len * len / 12.0);
            let (q, v) = (&q[3 * k..3 * k + 3], &v[3 * k..3 * k + 3]);
            0.5 * m * (v[0] * v[0] + v[1] * v[1]) + 0.5 * i * v[2] * v[2] + m * g * q[1]
        })
        .sum()
}

/// The humanoid tumbling: each body turned and turning its own way, the torso drifting.
pub fn humanoid_start() -> (Vec<f64>, Vec<f64>) {
    let n = HUMANOID.len();
    let attitudes: Vec<Matrix3<f64>> = (0..n)
        .map(|k| {
            let turn = Vector3::new(0.3 * k as f64, -0.2, 0.1 * (k % 3) as f64);
            Rotation3::new(turn).into_inner()
        })
        .collect();
    let omegas: Vec<Vector3<f64>> = (0..n)
        .map(|k| Vector3::new((k as f64).sin(), 2.0 * (k as f64).cos(), 0.5))
        .collect();
    let moving = (Vector3::new(0.1, 0.0, 0.2), Vector3::new(0.3, -0.1, 0.0));
    tree_state(&HUMANOID, &attitudes, &omegas, moving)
}

/// The humanoid's skeleton at positions `q` as one path through its joints and ends (a hand, the
/// arms, the torso, the legs), its left hand and its centre of mass.
pub fn humanoid_skeleton(q: &[f64]) -> (Vec<[f64; 3]>, [f64; 3], [f64; 3]) {
    let body = |k: usize| {
        let q = &q[12 * k..12 * k + 12];
        (
            Vector3::new(q[0], q[1], q[2]),
            Matrix3::from_row_slice(&q[3..12]),
        )
    };
    // A limb's joint with its parent and its far end.
    let top = |k: usize| {
        let (x, r) = body(k);
        (x + r * Vector3::from(HUMANOID[k].at_self)).into()
    };
    let end = |k: usize| {
        let (x, r) = body(k);
        (x - r * Vector3::from(HUMANOID[k].at_self)).into()
    };
    let (centre, _) = body(0);
    let path = vec![
        end(2),
        top(2),
        top(1),
        top(3),
        top(4),
        end(4),
        top(4),
        top(3),
        centre.into(),
        top(7),
        top(8),
        end(8),
        top(8),
        top(7),
        top(5),
        top(6),
        end(6),
    ];
    let mass: f64 = HUMANOID.iter().map(|limb| limb.m).sum();
    let weighted = (0..HUMANOID.len()).map(|k| body(k).0 * HUMANOID[k].m);
    let of_mass = weighted.fold(Vector3::zeros(), |sum, x| sum + x) / mass;
    (path, end(2), of_mass.into())
}

/// A time and [`humanoid_skeleton`] at it.
pub type Skeleton = (f64, Vec<[f64; 3]>, [f64; 3], [f64; 3]);

/// The free humanoid over `steps` steps of `h`: its [`Skeleton`] every `every`-th state.
pub fn humanoid_motion(h: f64, steps: u64, every: u64) -> Result<Vec<Skeleton>, DiracError> {
    let mut tree = tree(&HUMANOID, 0.0, h)?;
    let (q0, v0) = humanoid_start();
    tree.start_from_velocity(&q0, &v0)?;
    let mut frames = Vec::new();
    for k in 0..=steps {
        if k % every == 0 {
            let (path, hand, centre) = humanoid_skeleton(tree.q().as_slice());
            frames.push((tree.t(), path, hand, centre));
        }
        if k < steps {
            tree.step()?;
        }
    }
    Ok(frames)
}

/// The tour's rows: the four-bar and the slider-crank against one model with their joints as
/// holonomic constraints (positions apart, the joints' largest violation, the energy's error),
/// and the free humanoid (its momenta's drift).
pub fn reports() -> Result<Vec<Report>, DiracError> {
    let (g, h, steps) = (9.81, 0.002, 2000);
    let [a, b, c, d] = FOUR_BAR;
    let four_bar = against_one(
        "four-bar (joints)",
        four_bar(g, h)?,
        FourBarMonolithic { a, b, c, d, g },
        four_bar_state(1.0, 2.0),
        (h, steps),
    )?;
    let [a, b] = SLIDER_CRANK;
    let slider_crank = against_one(
        "slider-crank (joints)",
        slider_crank(g, h)?,
        SliderCrankMonolithic { a, b, g },
        slider_crank_state(0.8, 3.0),
        (h, steps),
    )?;
    let start = Instant::now();
    let (h, steps) = (0.005, 2000);
    let mut humanoid = tree(&HUMANOID, 0.0, h)?;
    let (q0, v0) = humanoid_start();
    humanoid.start_from_velocity(&q0, &v0)?;
    let momenta = |m: &Modular| bodies_momenta(m.q().as_slice(), m.p().as_slice());
    let (linear0, angular0) = momenta(&humanoid);
    let e0: f64 = humanoid.energies()?.iter().sum();
    let (mut drift, mut violation, mut energy): (f64, f64, f64) = (0.0, 0.0, 0.0);
    for _ in 0..steps {
        humanoid.step()?;
        let (linear, angular) = momenta(&humanoid);
        drift = drift
            .max((linear - linear0).amax())
            .max((angular - angular0).amax());
        violation = violation.max(humanoid.constraint_violation()?);
        energy = energy.max((humanoid.energies()?.iter().sum::<f64>() - e0).abs());
    }
    let humanoid = Report {
        scene: "humanoid (joints)",
        quadrature: "midpoint".into(),
        h,
        steps,
        max_energy_error: Some(energy),
        wall: start.elapsed(),
        check: format!("momenta to {drift:.0e}; joints to {violation:.0e}"),
    };
    Ok(vec![four_bar, slider_crank, humanoid])
}

/// A mechanism and the one model with its joints as holonomic constraints, stepped side by side
/// from `(q0, v0)` by `steps` steps of `h`: the tour's row.
fn against_one<S: DiracSystem<9>>(
    scene: &'static str,
    mut joined: Modular,
    model: S,
    (q0, v0): (Vec<f64>, Vec<f64>),
    (h, steps): (f64, u64),
) -> Result<Report, DiracError> {
    let start = Instant::now();
    let mut one = Stepper::new(model, Quadrature::midpoint(), h)?;
    joined.start_from_velocity(&q0, &v0)?;
    one.start_from_velocity(
        SVector::from_column_slice(&q0),
        SVector::from_column_slice(&v0),
    )?;
    let e0: f64 = joined.energies()?.iter().sum();
    let (mut apart, mut violation, mut energy): (f64, f64, f64) = (0.0, 0.0, 0.0);
    for _ in 0..steps {
        joined.step()?;
        one.step()?;
        let q = joined.q();
        apart = apart.max((q - SVector::<f64, 9>::from_column_slice(one.q().as_slice())).amax());
        violation = violation.max(joined.constraint_violation()?);
        energy = energy.max((joined.energies()?.iter().sum::<f64>() - e0).abs());
    }
    Ok(Report {
        scene,
        quadrature: "midpoint".into(),
        h,
        steps,
        max_energy_error: Some(energy),
        wall: start.elapsed(),
        check: format!("= one model to {apart:.0e}; joints to {violation:.0e}"),
    })
}
