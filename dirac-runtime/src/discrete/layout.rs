//! The unknowns of a Lagrangian step and the rows of its equations, in one order.

/// Where each unknown of a step sits in `x = [ξ_1, …, ξ_s, μ, λ]`: `s` blocks of `N` chart
/// coordinates (the internal points, then the end point), one multiplier per one-form and
/// quadrature node of a Galerkin step (`μ_{i,a}` pairs with `A_a(Q(c_i)) Q̇(c_i) = 0`; a single
/// one for a degree-1 step), and one per holonomic constraint and point of the path `j = 1..s`
/// (the constraint holds at every point: `λ_{j,b}` pairs with `g_b(Q_j) = 0`; the end point's
/// `λ_{s,b}` is SHAKE's, applied at `q_k`). The Euler–Lagrange rows use the same blocks. A
/// step projected onto `p = ϑ(q)` (a Lagrangian linear in the velocities under
/// [`FirstOrderScheme::SymmetricProjection`](crate::FirstOrderScheme)) ends with one projection
/// multiplier per coordinate.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Layout {
    coordinates: usize,
    points: usize,
    one_forms: usize,
    holonomic: usize,
    projection: usize,
}

impl Layout {
    pub(crate) fn new(
        coordinates: usize,
        points: usize,
        one_forms: usize,
        holonomic: usize,
    ) -> Self {
        Self {
            coordinates,
            points,
            one_forms,
            holonomic,
            projection: 0,
        }
    }

    /// The same layout with `projection` projection multipliers at its end (0 for none).
    pub(crate) fn with_projection(self, projection: usize) -> Self {
        Self { projection, ..self }
    }

    /// The predictor of a step: `previous` (the stepper's extrapolation of the last solutions)
    /// where there is one of the right size, else the path `ξ_j = c_j h ξ̇` along the chart
    /// velocity `xi_dot()` (`c_j = j/s`) with zero multipliers.
    pub(crate) fn predict<const N: usize>(
        &self,
        previous: Option<&nalgebra::DVector<f64>>,
        xi_dot: impl FnOnce() -> nalgebra::SVector<f64, N>,
        h: f64,
        x: &mut nalgebra::DVector<f64>,
    ) {
        match previous {
            Some(previous) if previous.len() == x.len() => {
                x.copy_from_slice(previous.as_slice());
            }
            _ => {
                let xi_dot = xi_dot();
                x.as_mut_slice().fill(0.0);
                let s = self.points;
                for j in 1..=s {
                    let c = j as f64 / s as f64;
                    x.fixed_rows_mut::<N>(self.point(j))
                        .copy_from(&(xi_dot * (c * h)));
                }
            }
        }
    }

    /// Number of unknowns.
    pub(crate) fn len(&self) -> usize {
        self.projection() + self.projection
    }

    /// First column of the projection multipliers (one per coordinate, when there are any).
    pub(crate) fn projection(&self) -> usize {
        self.coordinates * self.points + (self.one_forms + self.holonomic) * self.points
    }

    /// Number of points solved for, `s` (the internal points and the end point).
    pub(crate) fn points(&self) -> usize {
        self.points
    }

    /// First column of point `j` (`1..=s`).
    pub(crate) fn point(&self, j: usize) -> usize {
        (j - 1) * self.coordinates
    }

    /// First column of the end point `ξ_s`.
    pub(crate) fn end_point(&self) -> usize {
        self.point(self.points)
    }

    /// First multiplier column.
    pub(crate) fn multipliers(&self) -> usize {
        self.coordinates * self.points
    }

    /// Column of the multiplier of one-form `a` (of a degree-1 step).
    pub(crate) fn one_form(&self, a: usize) -> usize {
        self.one_form_at(0, a)
    }

    /// Column of the multiplier of one-form `a` at quadrature node `i` (`0..s`).
    pub(crate) fn one_form_at(&self, i: usize, a: usize) -> usize {
        self.multipliers() + i * self.one_forms + a
    }

    /// Column of the multiplier of holonomic constraint `b` at the end point (SHAKE's).
    pub(crate) fn holonomic(&self, b: usize) -> usize {
        self.holonomic_at(self.points, b)
    }

    /// Column of the multiplier of holonomic constraint `b` at point `j` (`1..=s`).
    pub(crate) fn holonomic_at(&self, j: usize, b: usize) -> usize {
        self.multipliers() + self.one_forms * self.points + (j - 1) * self.holonomic + b
    }

    /// What unknown `column` is, with `coordinate` naming coordinates.
    pub(crate) fn name(&self, column: usize, coordinate: &dyn Fn(usize) -> String) -> String {
        if column >= self.projection() {
            let coordinate = coordinate(column - self.projection());
            return format!("the multiplier projecting {coordinate} onto p = ϑ(q)");
        }
        if column >= self.multipliers() {
            let c = column - self.multipliers();
            let forms = self.one_forms * self.points;
            return if c < forms && self.points == 1 {
                format!("the multiplier of one-form {c}")
            } else if c < forms {
                let (i, a) = (c / self.one_forms, c % self.one_forms);
                format!(
                    "the multiplier of one-form {a} at quadrature node {}",
                    i + 1
                )
            } else {
                let c = c - forms;
                let (j, b) = (c / self.holonomic + 1, c % self.holonomic);
                if j == self.points {
                    format!("the multiplier of holonomic constraint {b}")
                } else {
                    format!("the multiplier of holonomic constraint {b} at internal point {j}")
                }
            };
        }
        let slot = match column / self.coordinates + 1 {
            j if j == self.points => "q_{k+1}".to_string(),
            j => format!("internal point {j}"),
        };
        format!("{} ({slot})", coordinate(column % self.coordinates))
    }
}
