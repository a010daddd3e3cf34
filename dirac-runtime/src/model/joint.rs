//! Joints: holonomic junctions between points carried by components, the links of a mechanism
//! in maximal coordinates.
//!
//! A [`Junction`](crate::Junction) is a constant one-form. A joint is a constraint on the
//! positions of the components it joins, `g(q^A, q^B) = 0`, with rows that are not linear in
//! them: two points held together (a ball joint in space, a pin in the plane), two points held
//! at a distance (a massless rod), an axis of one body held along an axis of the other (a
//! hinge) or across it (a universal joint), two frames held parallel (a weld), or parallel
//! with the points on a line (a slider). Each end is an [`Anchor`]: a point fixed in space, a point whose coordinates are a
//! component's own (a point mass), or a point fixed in a body: `x + R a` for a body at `x`
//! turned by the rotation `R`, `(x, y) + Rot(θ) a` in the plane.
//!
//! The modular step ([`Modular::connect`](crate::modular::Modular::connect)) holds a joint as
//! SHAKE holds a holonomic constraint: its impulse `G(q_k)ᵀ μ` on the row of `p_k`, with
//! `G = ∂g/∂q` read in each component's chart, and `g(q_{k+1}) = 0` at the step's end.
//!
//! ```
//! use dirac_runtime::joint::{Anchor, Joint};
//! // A rod of length 1 from the origin to a point mass at (x, y).
//! let rod = Joint::rod("rod", Anchor::fixed([0.0, 0.0]), Anchor::point("bob", ["x", "y"]), 1.0);
//! assert_eq!(rod.rows(), 1);
//! // A hinge about the body's x axis at the origin.
//! let hinge = Joint::revolute(
//!     "hinge",
//!     Anchor::fixed([0.0, 0.0, 0.0]),
//!     Anchor::body("link", ["x", "y", "z"], "R", [0.0, 0.0, 0.5]),
//!     [1.0, 0.0, 0.0],
//!     [1.0, 0.0, 0.0],
//! );
//! assert_eq!(hinge.rows(), 5);
//! ```

use crate::base::error::DiracError;

/// One end of a [`Joint`]: where it sits.
#[derive(Debug, Clone, PartialEq)]
pub struct Anchor {
    pub(crate) place: Place,
}

/// The kinds of anchor.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Place {
    /// A point fixed in space (2 or 3 numbers).
    Fixed(Vec<f64>),
    /// The point whose coordinates are the instance's positions `origin`.
    Point {
        instance: String,
        origin: Vec<String>,
    },
    /// `x + R a`: the body's origin, the rotation's name and `a` in the body's axes.
    Body {
        instance: String,
        origin: [String; 3],
        rotation: String,
        offset: [f64; 3],
    },
    /// `(x, y) + Rot(θ) a` in the plane.
    Planar {
        instance: String,
        origin: [String; 2],
        angle: String,
        offset: [f64; 2],
    },
}

impl Anchor {
    /// A point fixed in space (in the plane with two numbers).
    pub fn fixed<const D: usize>(point: [f64; D]) -> Self {
        Self {
            place: Place::Fixed(point.to_vec()),
        }
    }

    /// The point whose coordinates are the positions `origin` of the instance (a point mass).
    pub fn point<const D: usize>(instance: &str, origin: [&str; D]) -> Self {
        Self {
            place: Place::Point {
                instance: instance.into(),
                origin: origin.map(String::from).to_vec(),
            },
        }
    }

    /// The point `x + R a` of a rigid body: `x` the positions `origin`, `R` the rotation named
    /// `rotation` (its entries `rotation_11` … `rotation_33`), `a` the point in the body's axes.
    pub fn body(instance: &str, origin: [&str; 3], rotation: &str, offset: [f64; 3]) -> Self {
        Self {
            place: Place::Body {
                instance: instance.into(),
                origin: origin.map(String::from),
                rotation: rotation.into(),
                offset,
            },
        }
    }

    /// The point `(x, y) + Rot(θ) a` of a body in the plane: `(x, y)` the positions `origin`,
    /// `θ` the coordinate `angle`, `a` the point in the body's axes.
    pub fn planar(instance: &str, origin: [&str; 2], angle: &str, offset: [f64; 2]) -> Self {
        Self {
            place: Place::Planar {
                instance: instance.into(),
                origin: origin.map(String::from),
                angle: angle.into(),
                offset,
            },
        }
    }

    /// The instance the anchor is on (`None`: fixed in space).
    pub fn instance(&self) -> Option<&str> {
        match &self.place {
            Place::Fixed(_) => None,
            Place::Point { instance, .. }
            | Place::Body { instance, .. }
            | Place::Planar { instance, .. } => Some(instance),
        }
    }

    /// The dimension of the space the point lies in.
    pub(crate) fn dimension(&self) -> usize {
        match &self.place {
            Place::Fixed(p) => p.len(),
            Place::Point { origin, .. } => origin.len(),
            Place::Body { .. } => 3,
            Place::Planar { .. } => 2,
        }
    }

    /// The names of the positions the anchor reads, in the order [`Anchor::evaluate`] takes
    /// their indices: the origin, then the rotation's nine entries (row by row) or the angle.
    pub(crate) fn position_names(&self) -> Vec<String> {
        match &self.place {
            Place::Fixed(_) => Vec::new(),
            Place::Point { origin, .. } => origin.clone(),
            Place::Body {
                origin, rotation, ..
            } => {
                let entries = (1..=3).flat_map(|i| (1..=3).map(move |j| (i, j)));
                let mut names = origin.to_vec();
                names.extend(entries.map(|(i, j)| format!("{rotation}_{i}{j}")));
                names
            }
            Place::Planar { origin, angle, .. } => {
                let mut names = origin.to_vec();
                names.push(angle.clone());
                names
            }
        }
    }

    /// Whether the anchor turns with a frame an axis can be fixed in (a body, in space or in
    /// the plane, or space itself); a point mass has none.
    fn has_axes(&self) -> bool {
        !matches!(self.place, Place::Point { .. })
    }

    /// What it carries at the positions `q` of its component (`at`: the indices of
    /// [`position_names`](Self::position_names) in `q`): its point, an axis of its frame, or its
    /// frame's angle in the plane.
    fn carry<'a>(&'a self, q: &'a [f64], at: &'a [usize], what: Carrier) -> Carried<'a> {
        let mut value = [0.0; 3];
        match (&self.place, what) {
            (Place::Fixed(p), Carrier::Point) => value[..p.len()].copy_from_slice(p),
            (Place::Point { origin, .. }, Carrier::Point) => {
                for i in 0..origin.len() {
                    value[i] = q[at[i]];
                }
            }
            (Place::Body { offset, .. }, Carrier::Point) => {
                for (i, v) in value.iter_mut().enumerate() {
                    *v = q[at[i]]
                        + (0..3)
                            .map(|l| q[at[3 + 3 * i + l]] * offset[l])
                            .sum::<f64>();
                }
            }
            (Place::Planar { offset, .. }, Carrier::Point) => {
                let (s, c) = q[at[2]].sin_cos();
                let [a, b] = *offset;
                value[0] = q[at[0]] + c * a - s * b;
                value[1] = q[at[1]] + s * a + c * b;
            }
            (Place::Body { .. }, Carrier::Axis(axis)) => {
                for (i, v) in value.iter_mut().enumerate() {
                    *v = (0..3).map(|l| q[at[3 + 3 * i + l]] * axis[l]).sum();
                }
            }
            (Place::Planar { .. }, Carrier::Axis(axis)) => {
                let (s, c) = q[at[2]].sin_cos();
                value[0] = c * axis[0] - s * axis[1];
                value[1] = s * axis[0] + c * axis[1];
            }
            (_, Carrier::Axis(axis)) => value = axis,
            (Place::Planar { .. }, Carrier::Angle) => value[0] = q[at[2]],
            (_, Carrier::Angle) => {}
        }
        Carried {
            anchor: self,
            q,
            at,
            what,
            value,
        }
    }
}

/// `d(Rot(θ) a)/dθ` in the plane.
fn turning(theta: f64, [a, b]: [f64; 2]) -> [f64; 2] {
    let (s, c) = theta.sin_cos();
    [-s * a - c * b, c * a - s * b]
}

/// What an end carries (see [`Anchor::carry`]).
#[derive(Debug, Clone, Copy)]
enum Carrier {
    Point,
    Axis([f64; 3]),
    Angle,
}

/// A vector of up to 3 numbers an end carries at its component's positions, its derivatives
/// read on demand.
#[derive(Debug, Clone, Copy)]
struct Carried<'a> {
    anchor: &'a Anchor,
    q: &'a [f64],
    at: &'a [usize],
    what: Carrier,
    value: [f64; 3],
}

impl Carried<'_> {
    /// `each(position, ∂value_i/∂position)` for the positions entry `i` depends on.
    #[inline]
    fn terms(&self, i: usize, mut each: impl FnMut(usize, f64)) {
        let (q, at) = (self.q, self.at);
        match (&self.anchor.place, self.what) {
            (Place::Point { .. }, Carrier::Point) => each(at[i], 1.0),
            (Place::Body { offset, .. }, Carrier::Point) => {
                each(at[i], 1.0);
                for (l, a) in offset.iter().enumerate() {
                    each(at[3 + 3 * i + l], *a);
                }
            }
            (Place::Body { .. }, Carrier::Axis(axis)) => {
                for (l, a) in axis.iter().enumerate() {
                    each(at[3 + 3 * i + l], *a);
                }
            }
            (Place::Planar { offset, .. }, Carrier::Point) => {
                each(at[i], 1.0);
                each(at[2], turning(q[at[2]], *offset)[i]);
            }
            (Place::Planar { .. }, Carrier::Axis(axis)) => {
                each(at[2], turning(q[at[2]], [axis[0], axis[1]])[i]);
            }
            (Place::Planar { .. }, Carrier::Angle) if i == 0 => each(at[2], 1.0),
            _ => {}
        }
    }
}

/// What a joint holds.
#[derive(Debug, Clone, PartialEq)]
enum Kind {
    /// The two points coincide.
    Spherical,
    /// The two points lie at this distance.
    Rod(f64),
    /// The points coincide and the axes (each in its end's frame) stay parallel.
    Revolute([f64; 3], [f64; 3]),
    /// The points coincide and the axes (each in its end's frame) stay perpendicular.
    Universal([f64; 3], [f64; 3]),
    /// The points coincide and the frames stay parallel.
    Fixed,
    /// The frames stay parallel and the points on a line along this axis of `a`'s frame.
    Prismatic([f64; 3]),
}

/// A holonomic junction between two [`Anchor`]s (see the [module](self)).
#[derive(Debug, Clone, PartialEq)]
pub struct Joint {
    name: String,
    kind: Kind,
    ends: [Anchor; 2],
}

impl Joint {
    /// Holds the two points together: a ball joint in space, a pin (a revolute joint) in the
    /// plane; as many rows as the points have coordinates.
    pub fn spherical(name: &str, a: Anchor, b: Anchor) -> Self {
        Self::new(name, Kind::Spherical, a, b)
    }

    /// Holds the two points at the distance `length` (a massless rod between them); one row,
    /// `(|r_a − r_b|² − length²) / (2 length)`.
    pub fn rod(name: &str, a: Anchor, b: Anchor, length: f64) -> Self {
        Self::new(name, Kind::Rod(length), a, b)
    }

    /// A hinge in space: the points coincide and the axis `axis_a` of `a`'s frame stays along
    /// the axis `axis_b` of `b`'s (each end a body, or fixed in space): five rows, the last two
    /// `u_a · w_1 = u_a · w_2 = 0` with `w_1, w_2` perpendicular to `axis_b` in `b`'s frame.
    pub fn revolute(name: &str, a: Anchor, b: Anchor, axis_a: [f64; 3], axis_b: [f64; 3]) -> Self {
        Self::new(name, Kind::Revolute(axis_a, axis_b), a, b)
    }

    /// A universal joint (a Cardan joint) in space: the points coincide and the axis `axis_a`
    /// of `a`'s frame stays perpendicular to the axis `axis_b` of `b`'s: four rows.
    pub fn universal(name: &str, a: Anchor, b: Anchor, axis_a: [f64; 3], axis_b: [f64; 3]) -> Self {
        Self::new(name, Kind::Universal(axis_a, axis_b), a, b)
    }

    /// Welds the ends: the points coincide and `b`'s frame stays parallel to `a`'s (no other
    /// relative attitude can be given: write the bodies with axes parallel where welded). In
    /// space six rows, the last three `(R_a e_x)·(R_b e_y)`, `(R_a e_x)·(R_b e_z)`,
    /// `(R_a e_y)·(R_b e_z)`; in the plane three, the last `θ_b − θ_a`.
    pub fn fixed(name: &str, a: Anchor, b: Anchor) -> Self {
        Self::new(name, Kind::Fixed, a, b)
    }

    /// A slider: `b`'s frame stays parallel to `a`'s and `b`'s point on the line through
    /// `a`'s along `axis` (in `a`'s frame; two numbers in the plane). In space five rows, the
    /// frames' three and `(r_b − r_a)·(R_a n_k)` for two `n_k` perpendicular to the axis; in
    /// the plane two, `θ_b − θ_a` and `(r_b − r_a)·Rot(θ_a) n`.
    pub fn prismatic<const D: usize>(name: &str, a: Anchor, b: Anchor, axis: [f64; D]) -> Self {
        let mut padded = [0.0; 3];
        for (p, x) in padded.iter_mut().zip(axis) {
            *p = x;
        }
        let axis = if D <= 3 { padded } else { [f64::NAN; 3] };
        Self::new(name, Kind::Prismatic(axis), a, b)
    }

    fn new(name: &str, kind: Kind, a: Anchor, b: Anchor) -> Self {
        Self {
            name: name.into(),
            kind,
            ends: [a, b],
        }
    }

    /// The joint's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Gives it the name `name` (a joint of an included interconnection).
    pub(crate) fn rename(&mut self, name: String) {
        self.name = name;
    }

    /// Its two ends.
    pub fn ends(&self) -> &[Anchor; 2] {
        &self.ends
    }

    /// The number of its rows (of multipliers).
    pub fn rows(&self) -> usize {
        let d = self.ends[0].dimension();
        match self.kind {
            Kind::Spherical => d,
            Kind::Rod(_) => 1,
            Kind::Revolute(..) => 5,
            Kind::Universal(..) => 4,
            Kind::Fixed if d == 3 => 6,
            Kind::Fixed => 3,
            Kind::Prismatic(_) if d == 3 => 5,
            Kind::Prismatic(_) => 2,
        }
    }

    /// The name of row `k`.
    pub fn row_name(&self, k: usize) -> String {
        format!("{}[{k}]", self.name)
    }

    /// `Err(InvalidInterconnection)` where the joint cannot be held: both ends fixed, ends in
    /// spaces of different dimensions or of a dimension other than 2 and 3, a length that is
    /// not positive and finite, an axis that is not finite and non-zero, or a hinge on an end
    /// without axes (a point mass, a body in the plane: there a pin is `spherical`).
    pub(crate) fn check(&self) -> Result<(), DiracError> {
        let invalid = |why: String| {
            Err(DiracError::InvalidInterconnection(format!(
                "joint {}: {why}",
                self.name
            )))
        };
        let [a, b] = &self.ends;
        if a.instance().is_none() && b.instance().is_none() {
            return invalid("both ends are fixed in space".into());
        }
        let finite = |v: &[f64]| v.iter().all(|x| x.is_finite());
        for end in &self.ends {
            let bad = match &end.place {
                Place::Fixed(p) => !finite(p),
                Place::Body { offset, .. } => !finite(offset),
                Place::Planar { offset, .. } => !finite(offset),
                Place::Point { .. } => false,
            };
            if bad {
                return invalid("a point that is not finite".into());
            }
        }
        let (da, db) = (a.dimension(), b.dimension());
        if da != db || !(2..=3).contains(&da) {
            return invalid(format!(
                "its ends lie in spaces of dimension {da} and {db}: both must be 2 or both 3"
            ));
        }
        let norm = |v: &[f64; 3]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
        let axis = |v: &[f64; 3]| norm(v).is_finite() && norm(v) > 0.0;
        let framed = a.has_axes() && b.has_axes();
        match &self.kind {
            Kind::Rod(length) if !(length.is_finite() && *length > 0.0) => {
                invalid(format!("the length {length} is not positive and finite"))
            }
            Kind::Revolute(u, w) | Kind::Universal(u, w) => {
                if !(framed && da == 3) {
                    return invalid(
                        "a hinge or a universal joint needs both ends turning with a frame in \
                         space (a body, or fixed); in the plane a pin is a spherical joint"
                            .into(),
                    );
                }
                if !(axis(u) && axis(w)) {
                    return invalid("an axis that is zero or not finite".into());
                }
                Ok(())
            }
            Kind::Fixed | Kind::Prismatic(_) if !framed => invalid(
                "a weld or a slider needs both ends turning with a frame (a body in space or in \
                 the plane, or fixed), not a point mass"
                    .into(),
            ),
            Kind::Prismatic(u) if !axis(u) => {
                invalid("an axis that is zero or not finite (or of more than 3 numbers)".into())
            }
            Kind::Prismatic(u) if da == 2 && (u[2] != 0.0 || u[0] == 0.0 && u[1] == 0.0) => {
                invalid("an axis in the plane is two numbers, not both zero".into())
            }
            _ => Ok(()),
        }
    }

    /// Its rows at the positions `qa`, `qb` of its ends' components (`at`: the indices of each
    /// anchor's [`position_names`](Anchor::position_names)): the values into `value`, the
    /// derivatives by `add(row, end, position, ∂)`; the size of the terms the rows sum.
    pub(crate) fn evaluate(
        &self,
        (qa, qb): (&[f64], &[f64]),
        at: &[Vec<usize>; 2],
        value: &mut [f64],
        add: impl FnMut(usize, usize, usize, f64),
    ) -> f64 {
        let [a, b] = &self.ends;
        let d = a.dimension();
        let mut rows = Rows { value, add, d };
        let carry = |end: usize, what| {
            let (anchor, q) = if end == 0 { (a, qa) } else { (b, qb) };
            anchor.carry(q, &at[end], what)
        };
        let axis = Carrier::Axis;
        let (ra, rb) = (carry(0, Carrier::Point), carry(1, Carrier::Point));
        let mut size: f64 = 0.0;
        // The frames held parallel from row `first`: three dots of their axes in space, the
        // angle in the plane.
        let parallel = |rows: &mut Rows<'_, _>, first: usize| {
            if d == 3 {
                let e = |k: usize| std::array::from_fn(|i| if i == k { 1.0 } else { 0.0 });
                for (row, (i, j)) in [(0, 1), (0, 2), (1, 2)].into_iter().enumerate() {
                    rows.dot(first + row, &carry(0, axis(e(i))), &carry(1, axis(e(j))));
                }
            } else {
                let (u, w) = (carry(0, Carrier::Angle), carry(1, Carrier::Angle));
                rows.value[first] = w.value[0] - u.value[0];
                rows.with(first, 0, &u, 0, -1.0);
                rows.with(first, 1, &w, 0, 1.0);
            }
        };
        match &self.kind {
            Kind::Spherical | Kind::Revolute(..) | Kind::Universal(..) | Kind::Fixed => {
                for i in 0..d {
                    rows.value[i] = ra.value[i] - rb.value[i];
                    size = size.max(ra.value[i].abs()).max(rb.value[i].abs());
                    rows.with(i, 0, &ra, i, 1.0);
                    rows.with(i, 1, &rb, i, -1.0);
                }
            }
            Kind::Rod(length) => {
                let r: [f64; 3] = std::array::from_fn(|i| ra.value[i] - rb.value[i]);
                let squared: f64 = r.iter().map(|x| x * x).sum();
                rows.value[0] = (squared - length * length) / (2.0 * length);
                size = (squared + length * length) / (2.0 * length);
                for (i, ri) in r.iter().enumerate().take(d) {
                    rows.with(0, 0, &ra, i, ri / length);
                    rows.with(0, 1, &rb, i, -ri / length);
                }
            }
            Kind::Prismatic(_) => {}
        }
        match &self.kind {
            Kind::Revolute(axis_a, axis_b) => {
                let u = carry(0, axis(*axis_a));
                for (k, perpendicular) in perpendiculars(axis_b).iter().enumerate() {
                    rows.dot(3 + k, &u, &carry(1, axis(*perpendicular)));
                }
                size = size.max(1.0);
            }
            Kind::Universal(axis_a, axis_b) => {
                let (u, w) = (carry(0, axis(unit(axis_a))), carry(1, axis(unit(axis_b))));
                rows.dot(3, &u, &w);
                size = size.max(1.0);
            }
            Kind::Fixed => {
                parallel(&mut rows, d);
                size = size.max(1.0);
            }
            Kind::Prismatic(along) => {
                // The frames, then the offset across the axis (read in `a`'s frame).
                parallel(&mut rows, 0);
                let first = if d == 3 { 3 } else { 1 };
                let across: Vec<[f64; 3]> = if d == 3 {
                    perpendiculars(along).to_vec()
                } else {
                    let n = unit(along);
                    vec![[-n[1], n[0], 0.0]]
                };
                let r: [f64; 3] = std::array::from_fn(|i| rb.value[i] - ra.value[i]);
                for (k, n) in across.iter().enumerate() {
                    let row = first + k;
                    let u = carry(0, axis(*n));
                    rows.value[row] = (0..d).map(|i| r[i] * u.value[i]).sum();
                    for (i, ri) in r.iter().enumerate().take(d) {
                        rows.with(row, 1, &rb, i, u.value[i]);
                        rows.with(row, 0, &ra, i, -u.value[i]);
                        rows.with(row, 0, &u, i, *ri);
                    }
                }
                let biggest = ra.value.iter().chain(&rb.value);
                size = size.max(biggest.fold(1.0, |m, x| m.max(x.abs())));
            }
            Kind::Spherical | Kind::Rod(_) => {}
        }
        size
    }
}

/// A joint's rows as they are written: their values and, through `add(row, end, position, ∂)`,
/// their derivatives; `d` the dimension of the space the ends lie in.
struct Rows<'v, F> {
    value: &'v mut [f64],
    add: F,
    d: usize,
}

impl<F: FnMut(usize, usize, usize, f64)> Rows<'_, F> {
    /// Row `row` gains `s` times the derivatives of entry `i` of what end `end` carries.
    fn with(&mut self, row: usize, end: usize, carried: &Carried, i: usize, s: f64) {
        let add = &mut self.add;
        carried.terms(i, |p, x| add(row, end, p, s * x));
    }

    /// Row `row` is `u · w`, `u` carried by end 0 and `w` by end 1.
    fn dot(&mut self, row: usize, u: &Carried, w: &Carried) {
        self.value[row] = (0..3).map(|i| u.value[i] * w.value[i]).sum();
        for i in 0..self.d {
            self.with(row, 0, u, i, w.value[i]);
            self.with(row, 1, w, i, u.value[i]);
        }
    }
}

/// `v` scaled to unit length.
fn unit(v: &[f64; 3]) -> [f64; 3] {
    let norm = v.iter().map(|x| x * x).sum::<f64>().sqrt();
    v.map(|x| x / norm)
}

/// Two unit vectors perpendicular to `axis` and to each other.
fn perpendiculars(axis: &[f64; 3]) -> [[f64; 3]; 2] {
    let norm = axis.iter().map(|x| x * x).sum::<f64>().sqrt();
    let n = axis.map(|x| x / norm);
    // The coordinate axis least along `n`, made perpendicular.
    let k = (0..3)
        .min_by(|&i, &j| n[i].abs().total_cmp(&n[j].abs()))
        .unwrap_or(0);
    let mut e = [0.0; 3];
    e[k] = 1.0;
    let cross = |a: &[f64; 3], b: &[f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let w1 = cross(&n, &e);
    let norm1 = w1.iter().map(|x| x * x).sum::<f64>().sqrt();
    let w1 = w1.map(|x| x / norm1);
    let w2 = cross(&n, &w1);
    [w1, w2]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The rows' derivatives against central differences in every position.
    #[test]
    fn the_rows_derivatives_are_their_values_differences() {
        // A body turned about an oblique axis, a planar body, point masses.
        let (s, c) = 0.7_f64.sin_cos();
        let body = [0.3, -0.2, 0.9, c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0];
        let reversed = || body.iter().rev().copied().collect::<Vec<f64>>();
        let (first, second) = (
            || Anchor::body("a", ["x", "y", "z"], "R", [0.1, 0.2, 0.5]),
            || Anchor::body("b", ["x", "y", "z"], "R", [0.0, -0.3, 0.2]),
        );
        let cases = [
            (
                Joint::revolute("hinge", first(), second(), [1.0, 0.0, 0.0], [0.0, 1.0, 1.0]),
                body.to_vec(),
                reversed(),
            ),
            (
                Joint::spherical(
                    "pin",
                    Anchor::planar("a", ["x", "y"], "t", [0.4, -0.1]),
                    Anchor::point("b", ["x", "y"]),
                ),
                vec![0.2, 0.5, 1.1],
                vec![-0.3, 0.8],
            ),
            (
                Joint::rod(
                    "rod",
                    Anchor::point("a", ["x", "y", "z"]),
                    Anchor::fixed([0.1, 0.0, 0.0]),
                    1.3,
                ),
                vec![0.2, 0.5, 1.1],
                vec![],
            ),
            (
                Joint::universal(
                    "cardan",
                    first(),
                    second(),
                    [1.0, 0.5, 0.0],
                    [0.0, 1.0, 1.0],
                ),
                body.to_vec(),
                reversed(),
            ),
            (
                Joint::fixed("weld", first(), second()),
                body.to_vec(),
                reversed(),
            ),
            (
                Joint::prismatic("slider", first(), second(), [0.3, -1.0, 0.4]),
                body.to_vec(),
                reversed(),
            ),
            (
                Joint::prismatic(
                    "planar slider",
                    Anchor::planar("a", ["x", "y"], "t", [0.4, -0.1]),
                    Anchor::planar("b", ["x", "y"], "t", [-0.2, 0.3]),
                    [1.0, 2.0],
                ),
                vec![0.2, 0.5, 1.1],
                vec![-0.3, 0.8, -0.6],
            ),
            (
                Joint::fixed(
                    "planar weld",
                    Anchor::fixed([0.3, 0.1]),
                    Anchor::planar("b", ["x", "y"], "t", [-0.2, 0.3]),
                ),
                vec![],
                vec![-0.3, 0.8, -0.6],
            ),
        ];
        for (joint, qa, qb) in cases {
            joint.check().unwrap();
            let at = [
                (0..joint.ends[0].position_names().len()).collect(),
                (0..joint.ends[1].position_names().len()).collect(),
            ];
            let rows = joint.rows();
            let (mut value, mut terms) = (vec![0.0; rows], Vec::new());
            let add = |row, end, position, a| terms.push((row, end, position, a));
            joint.evaluate((&qa, &qb), &at, &mut value, add);
            for end in 0..2 {
                let n = [qa.len(), qb.len()][end];
                for p in 0..n {
                    let h = 1e-6;
                    let moved = |sign: f64| {
                        let (mut a, mut b) = (qa.clone(), qb.clone());
                        [&mut a, &mut b][end][p] += sign * h;
                        let mut v = vec![0.0; rows];
                        joint.evaluate((&a, &b), &at, &mut v, |_, _, _, _| {});
                        v
                    };
                    let (up, down) = (moved(1.0), moved(-1.0));
                    for row in 0..rows {
                        let exact: f64 = terms
                            .iter()
                            .filter(|t| t.0 == row && t.1 == end && t.2 == p)
                            .map(|t| t.3)
                            .sum();
                        let difference = (up[row] - down[row]) / (2.0 * h);
                        assert!(
                            (exact - difference).abs() < 1e-8,
                            "{} row {row} end {end} position {p}: {exact} vs {difference}",
                            joint.name
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn joints_that_cannot_be_held_are_refused() {
        let fixed = || Anchor::fixed([0.0, 0.0, 0.0]);
        let mass = || Anchor::point("m", ["x", "y", "z"]);
        let planar = || Anchor::planar("p", ["x", "y"], "t", [1.0, 0.0]);
        let fixed2 = || Anchor::fixed([0.0, 0.0]);
        let body = || Anchor::body("b", ["x", "y", "z"], "R", [0.0, 0.0, 1.0]);
        let refused = [
            (
                Joint::spherical("both fixed", fixed(), fixed()),
                "both ends are fixed",
            ),
            (
                Joint::spherical("dimensions", planar(), mass()),
                "dimension 2 and 3",
            ),
            (
                Joint::rod("length", fixed(), mass(), 0.0),
                "length 0 is not positive",
            ),
            (
                Joint::revolute("no axes", fixed(), mass(), [1.0, 0.0, 0.0], [1.0, 0.0, 0.0]),
                "a hinge or a universal joint needs both ends turning",
            ),
            (
                Joint::revolute(
                    "planar",
                    planar(),
                    planar(),
                    [1.0, 0.0, 0.0],
                    [1.0, 0.0, 0.0],
                ),
                "in the plane a pin is a spherical joint",
            ),
            (Joint::fixed("weld", mass(), body()), "not a point mass"),
            (
                Joint::prismatic("slider", body(), body(), [0.0, 0.0, 0.0]),
                "an axis that is zero",
            ),
            (
                Joint::prismatic("upright", planar(), fixed2(), [0.0, 0.0, 1.0]),
                "an axis in the plane is two numbers",
            ),
            (
                Joint::revolute("zero axis", fixed(), body(), [0.0; 3], [1.0, 0.0, 0.0]),
                "an axis that is zero",
            ),
            (
                Joint::spherical("not finite", Anchor::fixed([f64::NAN, 0.0, 0.0]), mass()),
                "not finite",
            ),
        ];
        for (joint, why) in refused {
            let error = joint.check().unwrap_err().to_string();
            assert!(
                error.contains(&format!("joint {}: ", joint.name())),
                "{error}"
            );
            assert!(error.contains(why), "{error}");
        }
        assert!(Joint::rod("fine", fixed(), mass(), 1.0).check().is_ok());
    }
}
