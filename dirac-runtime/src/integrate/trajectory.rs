//! Recorded trajectories: time, positions, velocities, momenta, energy and the work done on the
//! model, with the run's metadata, the energy balance, columns by name and CSV output.

use std::io::Write;
use std::path::Path;

use thiserror::Error;

use crate::base::error::DiracError;
use crate::integrate::event::Crossing;
use crate::space::manifold::{Manifold, Vectors};
use crate::step::dense_output::Sample;

/// What produced a trajectory: the model, the method and the solver's tolerances.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Metadata {
    /// The model's type name.
    pub model: String,
    /// The quadrature, in the attribute's syntax ([`Quadrature::name`](crate::Quadrature::name)).
    pub quadrature: String,
    /// The step size.
    pub h: f64,
    /// The time the run started from.
    pub t0: f64,
    /// Newton's relative residual tolerance.
    pub residual_tolerance: f64,
    /// Newton's relative update tolerance.
    pub step_tolerance: f64,
}

/// A sampled trajectory `(t, q, v, p, E)` of a system with `N` coordinates on the manifold `M`
/// (`Rᴺ` unless named).
///
/// ```
/// use dirac_runtime::{Sample, Trajectory};
/// use nalgebra::vector;
/// let mut trajectory = Trajectory::<1>::new(vec!["x".into()])?;
/// assert!(Trajectory::<1>::new(vec![]).is_err()); // one name per coordinate
/// let sample = |t, q, v| Sample { t, q: vector![q], v: vector![v], p: vector![v] };
/// trajectory.push(&sample(0.0, 1.0, 0.0), 0.5)?;
/// trajectory.push(&sample(0.1, 0.99, -0.1), 0.5001)?;
/// let mut csv = Vec::new();
/// trajectory.write_csv(&mut csv)?;
/// assert!(String::from_utf8(csv).unwrap().starts_with("t,x,v_x,p_x,energy\n0,1,0,0,0.5\n"));
/// assert!((trajectory.max_energy_error() - 1e-4).abs() < 1e-12);
/// assert_eq!(trajectory.column("v_x"), Some(vec![0.0, -0.1]));
/// # Ok::<(), dirac_runtime::DiracError>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(
    feature = "serde",
    serde(bound(
        serialize = "M::Point<f64>: serde::Serialize, M::Tangent<f64>: serde::Serialize",
        deserialize = "M::Point<f64>: serde::Deserialize<'de>, \
                       M::Tangent<f64>: serde::Deserialize<'de>"
    ))
)]
pub struct Trajectory<const N: usize, M: Manifold<N> = Vectors> {
    /// The model's variables.
    names: Vec<String>,
    metadata: Option<Metadata>,
    t: Vec<f64>,
    q: Vec<M::Point<f64>>,
    v: Vec<M::Tangent<f64>>,
    p: Vec<M::Tangent<f64>>,
    energy: Vec<f64>,
    /// The work done by the forces and inputs from the stepper's start to each sample (see
    /// [`Stepper::work`](crate::Stepper::work)); `None` once a sample came without it.
    work: Option<Vec<f64>>,
    /// Whether the model has forces that can do work: the `work` column is shown only then.
    forced: bool,
    /// Names of the multipliers (empty for an unconstrained system).
    multiplier_names: Vec<String>,
    /// The multipliers of every sample in one buffer, `multiplier_names.len()` per sample (one
    /// allocation for the run, not one per sample).
    multipliers: Vec<f64>,
    violation: Vec<f64>,
}

impl<const N: usize, M: Manifold<N>> Trajectory<N, M> {
    /// An empty trajectory whose variables are called `names` (one per coordinate on `Rᴺ`; see
    /// [`DiracSystem::coordinate_name`](crate::DiracSystem::coordinate_name)).
    pub fn new(names: Vec<String>) -> Result<Self, DiracError> {
        Self::with_multipliers(names, Vec::new())
    }

    /// An empty trajectory of a constrained system, which also records the constraint
    /// violation and the multipliers (named `multiplier_names`) at every sample.
    pub fn with_multipliers(
        names: Vec<String>,
        multiplier_names: Vec<String>,
    ) -> Result<Self, DiracError> {
        if names.len() != M::VARIABLES {
            return Err(DiracError::Dimension(format!(
                "a trajectory of {} variables needs {} names, got {}",
                M::VARIABLES,
                M::VARIABLES,
                names.len()
            )));
        }
        Ok(Self {
            names,
            metadata: None,
            t: Vec::new(),
            q: Vec::new(),
            v: Vec::new(),
            p: Vec::new(),
            energy: Vec::new(),
            work: Some(Vec::new()),
            forced: true,
            multiplier_names,
            multipliers: Vec::new(),
            violation: Vec::new(),
        })
    }

    /// The same trajectory, recording what produced it.
    pub fn with_metadata(self, metadata: Metadata) -> Self {
        Self {
            metadata: Some(metadata),
            ..self
        }
    }

    /// The same trajectory of a model without forces (`forced` false): the work, zero, is kept
    /// for the balance but not shown as a column.
    pub(crate) fn with_forces(self, forced: bool) -> Self {
        Self { forced, ..self }
    }

    /// What produced the trajectory (set by [`Stepper`](crate::Stepper)'s runs).
    pub fn metadata(&self) -> Option<&Metadata> {
        self.metadata.as_ref()
    }

    /// Appends a sample of a constrained system: one multiplier per name given at construction.
    pub fn push_constrained(
        &mut self,
        sample: &Sample<N, M>,
        energy: f64,
        violation: f64,
        multipliers: &[f64],
    ) -> Result<(), DiracError> {
        if multipliers.len() != self.multiplier_names.len() {
            return Err(DiracError::Dimension(format!(
                "the trajectory records {} multipliers, got {}",
                self.multiplier_names.len(),
                multipliers.len()
            )));
        }
        self.record(sample, energy, None, Some((violation, multipliers)))
    }

    /// Appends a sample with the work done up to it (`None`: unknown, which drops the work
    /// column) and, for a constrained system, its violation and multipliers.
    pub(crate) fn record(
        &mut self,
        sample: &Sample<N, M>,
        energy: f64,
        work: Option<f64>,
        constraint: Option<(f64, &[f64])>,
    ) -> Result<(), DiracError> {
        let expected = self.multiplier_names.len();
        let given = constraint.map_or(0, |(_, m)| m.len());
        if constraint.is_some() != (expected > 0) || given != expected {
            return Err(DiracError::Dimension(
                if expected > 0 && constraint.is_none() {
                    format!("the trajectory records {expected} multipliers: use push_constrained")
                } else {
                    format!("the trajectory records {expected} multipliers, got {given}")
                },
            ));
        }
        self.t.push(sample.t);
        self.q.push(sample.q);
        self.v.push(sample.v);
        self.p.push(sample.p);
        self.energy.push(energy);
        match (&mut self.work, work) {
            (Some(column), Some(work)) => column.push(work),
            _ => self.work = None,
        }
        if let Some((violation, multipliers)) = constraint {
            self.violation.push(violation);
            self.multipliers.extend_from_slice(multipliers);
        }
        Ok(())
    }

    /// Makes room for `additional` more samples, so that recording them allocates nothing.
    ///
    /// ```
    /// use dirac_runtime::Trajectory;
    /// let mut trajectory = Trajectory::<1>::new(vec!["x".into()])?;
    /// trajectory.reserve(1000);
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn reserve(&mut self, additional: usize) {
        self.t.reserve(additional);
        self.q.reserve(additional);
        self.v.reserve(additional);
        self.p.reserve(additional);
        self.energy.reserve(additional);
        if let Some(work) = &mut self.work {
            work.reserve(additional);
        }
        if !self.multiplier_names.is_empty() {
            self.violation.reserve(additional);
            self.multipliers
                .reserve(additional * self.multiplier_names.len());
        }
    }

    /// Names of the recorded multipliers (empty for an unconstrained system).
    pub fn multiplier_names(&self) -> &[String] {
        &self.multiplier_names
    }

    /// Constraint violation of the step that ended at each sample (empty when unconstrained).
    pub fn constraint_violation(&self) -> &[f64] {
        &self.violation
    }

    /// Multipliers of the step that ended at each sample, one slice per sample (none when
    /// unconstrained).
    pub fn multipliers(&self) -> std::slice::ChunksExact<'_, f64> {
        self.multipliers
            .chunks_exact(self.multiplier_names.len().max(1))
    }

    /// Multipliers of the step that ended at sample `k` (`None` when unconstrained or past the
    /// end).
    pub fn multipliers_at(&self, k: usize) -> Option<&[f64]> {
        let m = self.multiplier_names.len();
        (m > 0 && k < self.len()).then(|| &self.multipliers[k * m..(k + 1) * m])
    }

    /// The largest constraint violation over the trajectory.
    pub fn max_constraint_violation(&self) -> f64 {
        self.violation.iter().cloned().fold(0.0, f64::max)
    }

    /// Appends a sample of an unconstrained system; a trajectory that records multipliers takes
    /// [`push_constrained`](Self::push_constrained) instead (an error here). A sample pushed by
    /// hand carries no work: the trajectory then has no work column.
    pub fn push(&mut self, sample: &Sample<N, M>, energy: f64) -> Result<(), DiracError> {
        self.record(sample, energy, None, None)
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.t.len()
    }

    /// Whether there are no samples.
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }

    /// Coordinate names.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// Sample times.
    pub fn t(&self) -> &[f64] {
        &self.t
    }

    /// Positions.
    pub fn q(&self) -> &[M::Point<f64>] {
        &self.q
    }

    /// Velocities.
    pub fn v(&self) -> &[M::Tangent<f64>] {
        &self.v
    }

    /// Momenta.
    pub fn p(&self) -> &[M::Tangent<f64>] {
        &self.p
    }

    /// Energies.
    pub fn energy(&self) -> &[f64] {
        &self.energy
    }

    /// The work done on the model by its forces and inputs from the stepper's start to each
    /// sample ([`Stepper::work`](crate::Stepper::work)); `None` where some sample came without
    /// it: pushed by hand, interpolated between steps (`saveat`), or stepped by equations that
    /// do not report their work.
    pub fn work(&self) -> Option<&[f64]> {
        self.work.as_deref()
    }

    /// Sample `k`.
    pub fn sample(&self, k: usize) -> Option<Sample<N, M>> {
        (k < self.len()).then(|| Sample {
            t: self.t[k],
            q: self.q[k],
            v: self.v[k],
            p: self.p[k],
        })
    }

    /// `max_k |E_k − E_0|`: the largest energy error against the first sample (0 when empty).
    pub fn max_energy_error(&self) -> f64 {
        let Some(&e0) = self.energy.first() else {
            return 0.0;
        };
        self.energy.iter().fold(0.0, |m, e| m.max((e - e0).abs()))
    }

    /// The energy balance over the trajectory: the energy's change from the first sample to the
    /// last against the work done on the model by its forces and inputs, and the largest
    /// defect `|E_k − E_0 − (W_k − W_0)|` over the samples (see [`EnergyBalance`]).
    /// `Unsupported` without a work column ([`work`](Self::work)), `NotStarted` when empty.
    ///
    /// ```
    /// use dirac_runtime::{DiracSystem, Quadrature, Run, Scalar, Stepper};
    /// use nalgebra::{SVector, vector};
    /// /// A damped oscillator: L = (v² − q²)/2, F = −0.1 v dq.
    /// struct Damped;
    /// impl DiracSystem<1> for Damped {
    ///     const FORCES: bool = true;
    ///     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
    ///         (v[0] * v[0] - q[0] * q[0]) * 0.5
    ///     }
    ///     fn force<D: Scalar>(&self, _q: &SVector<D, 1>, v: &SVector<D, 1>, _t: f64, _u: &[D])
    ///         -> SVector<D, 1> {
    ///         SVector::from([v[0] * -0.1])
    ///     }
    /// }
    /// let mut stepper = Stepper::new(Damped, Quadrature::midpoint(), 0.1)?;
    /// stepper.start_from_velocity(vector![1.0], vector![0.0])?;
    /// let trajectory = stepper.solve(Run::until(20.0))?.trajectory;
    /// let balance = trajectory.energy_balance()?;
    /// assert!(balance.work < -0.4); // the damper took most of the energy 0.5
    /// assert!(balance.max_defect < 1e-14); // and the midpoint rule books every bit of it
    /// println!("{balance}");
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn energy_balance(&self) -> Result<EnergyBalance, DiracError> {
        let work = self.work.as_deref().ok_or_else(|| {
            DiracError::Unsupported(
                "the energy balance of a trajectory without a work column (a sample pushed by \
                 hand, interpolated between steps by saveat, or stepped by equations that do \
                 not report their work)"
                    .into(),
            )
        })?;
        let (Some(&e0), Some(&w0)) = (self.energy.first(), work.first()) else {
            return Err(DiracError::NotStarted);
        };
        let defect = |(e, w): (&f64, &f64)| (e - e0) - (w - w0);
        let max_defect = self
            .energy
            .iter()
            .zip(work)
            .fold(0.0_f64, |m, ew| m.max(defect(ew).abs()));
        let scale = self
            .energy
            .iter()
            .chain(work)
            .fold(0.0_f64, |m, x| m.max(x.abs()));
        Ok(EnergyBalance {
            initial: e0,
            last: self.energy[self.len() - 1],
            work: work[self.len() - 1] - w0,
            max_defect,
            scale,
        })
    }

    /// The largest defect of the energy balance over the samples,
    /// `max_k |E_k − E_0 − (W_k − W_0)|` (see [`energy_balance`](Self::energy_balance)).
    pub fn max_energy_balance_error(&self) -> Result<f64, DiracError> {
        self.energy_balance().map(|balance| balance.max_defect)
    }

    /// The names of the columns, in the CSV's order: `t`, the coordinates, `v_<coordinate>`,
    /// `p_<coordinate>`, `energy`, `work` (for a model with forces, where it is known, see
    /// [`work`](Self::work)), and for a constrained system `constraint_violation` and the
    /// multipliers. On a product manifold a rotation `R` has the columns `R_11` … `R_33`, its
    /// body angular velocity `v_R_x` … and momentum `p_R_x` …; a unit vector `n` has `n_x` …,
    /// `v_n_x` … and `p_n_x` … (see [`Manifold::point_names`]).
    pub fn column_names(&self) -> Vec<String> {
        let constrained = !self.multiplier_names.is_empty();
        let tangent = M::tangent_names(&self.names);
        std::iter::once("t".to_string())
            .chain(M::point_names(&self.names))
            .chain(tangent.iter().map(|n| format!("v_{n}")))
            .chain(tangent.iter().map(|n| format!("p_{n}")))
            .chain(std::iter::once("energy".to_string()))
            .chain((self.work.is_some() && self.forced).then(|| "work".to_string()))
            .chain(constrained.then(|| "constraint_violation".to_string()))
            .chain(self.multiplier_names.iter().cloned())
            .collect()
    }

    /// The column called `name` (one of [`column_names`](Self::column_names)), `None` if there
    /// is none.
    pub fn column(&self, name: &str) -> Option<Vec<f64>> {
        let index = self.column_names().iter().position(|c| c == name)?;
        Some((0..self.len()).map(|k| self.row(k)[index]).collect())
    }

    /// Row `k` in the order of [`column_names`](Self::column_names).
    fn row(&self, k: usize) -> Vec<f64> {
        let mut row = Vec::with_capacity(3 * N + 3 + self.multiplier_names.len());
        row.push(self.t[k]);
        row.extend(M::point_components(&self.q[k]));
        row.extend(M::tangent_components(&self.v[k]));
        row.extend(M::tangent_components(&self.p[k]));
        row.push(self.energy[k]);
        if let Some(work) = self.work.as_ref().filter(|_| self.forced) {
            row.push(work[k]);
        }
        if let (Some(v), Some(m)) = (self.violation.get(k), self.multipliers_at(k)) {
            row.push(*v);
            row.extend(m.iter());
        }
        row
    }

    /// Writes the columns ([`column_names`](Self::column_names)) as CSV with a header row.
    pub fn write_csv<W: Write>(&self, writer: W) -> Result<(), DiracError> {
        let io = |e: csv::Error| DiracError::Io(e.to_string());
        let mut w = csv::Writer::from_writer(writer);
        w.write_record(self.column_names()).map_err(io)?;
        for k in 0..self.len() {
            w.write_record(self.row(k).iter().map(|x| x.to_string()))
                .map_err(io)?;
        }
        w.flush().map_err(|e| DiracError::Io(e.to_string()))
    }

    /// Writes the CSV to a file, creating its directory if needed.
    pub fn save_csv(&self, path: impl AsRef<Path>) -> Result<(), DiracError> {
        self.write_csv(create(path.as_ref())?)
    }
}

/// The energy balance of a trajectory ([`Trajectory::energy_balance`]): how much the energy
/// changed, how much work the forces and inputs did, and how well the two agree.
///
/// Each step's work is the one the scheme uses ([`StepWork`](crate::StepWork)), so that for
/// the midpoint rule and Gauss–Galerkin steps on a model with a quadratic energy
/// (oscillators, circuits, linear mechanisms) `E_{k+1} − E_k = W_k` holds to round-off
/// whatever the forces and inputs are; elsewhere the defect is the scheme's energy error,
/// which falls with the step at the scheme's order.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct EnergyBalance {
    /// The energy at the first sample.
    pub initial: f64,
    /// The energy at the last sample.
    pub last: f64,
    /// The work done by the forces and inputs from the first sample to the last.
    pub work: f64,
    /// The largest defect `|E_k − E_0 − (W_k − W_0)|` over the samples.
    pub max_defect: f64,
    /// The largest energy or work in the balance: the defect's round-off floor is a few ulps
    /// of it.
    pub scale: f64,
}

impl std::fmt::Display for EnergyBalance {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "energy {:.6e} -> {:.6e}: change {:+.6e}, work of forces and inputs {:+.6e}, \
             largest balance defect {:.1e} ({:.1e} of the largest term)",
            self.initial,
            self.last,
            self.last - self.initial,
            self.work,
            self.max_defect,
            self.max_defect / self.scale.max(f64::MIN_POSITIVE)
        )
    }
}

/// A buffered new file at `path`, its directory created if needed.
pub(crate) fn create(path: &Path) -> Result<std::io::BufWriter<std::fs::File>, DiracError> {
    let io = |e: std::io::Error| DiracError::Io(format!("{}: {e}", path.display()));
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(io)?;
    }
    Ok(std::io::BufWriter::new(
        std::fs::File::create(path).map_err(io)?,
    ))
}

/// A run that stopped at a failing step: the trajectory and events up to the last good step,
/// and why.
///
/// `?` converts it into its [`DiracError`] (dropping the trajectory); match on it to keep the
/// steps made.
///
/// ```
/// use dirac_runtime::{DiracSystem, Quadrature, Scalar, Stepper};
/// use nalgebra::{SVector, vector};
/// /// L = v²/2 − √(1 − q): the potential ends at q = 1.
/// struct Edge;
/// impl DiracSystem<1> for Edge {
///     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
///         v[0] * v[0] * 0.5 - (-q[0] + 1.0).sqrt()
///     }
/// }
/// let mut stepper = Stepper::new(Edge, Quadrature::midpoint(), 0.1)?;
/// stepper.start_from_velocity(vector![0.0], vector![1.0])?;
/// let interrupted = stepper.run(100).unwrap_err();
/// assert_eq!(interrupted.trajectory.len() as u64, stepper.steps() + 1);
/// assert!(stepper.q()[0] < 1.0);
/// # Ok::<(), dirac_runtime::DiracError>(())
/// ```
#[derive(Debug, Clone, PartialEq, Error)]
#[error("the run stopped after {} samples: {error}", trajectory.len())]
pub struct Interrupted<const N: usize, M: Manifold<N> = Vectors> {
    /// Every sample recorded before the failing step.
    pub trajectory: Trajectory<N, M>,
    /// The event crossings located before the failing step.
    pub events: Vec<Crossing<N, M>>,
    /// Why the step failed.
    #[source]
    pub error: DiracError,
}

impl<const N: usize, M: Manifold<N>> From<Box<Interrupted<N, M>>> for DiracError {
    fn from(interrupted: Box<Interrupted<N, M>>) -> Self {
        interrupted.error
    }
}
