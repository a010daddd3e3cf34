//! The energy balance of a model made of components, component by component, from a
//! stepper's booked work (see [`Ledger`]).

use crate::base::error::DiracError;
use crate::integrate::stepper::Stepper;
use crate::model::interconnection::Interconnected;
use crate::space::manifold::Vectors;
use crate::step::ledger::{ComponentBalance, Ledger};
use crate::step::step_equations::StepEquations;

impl<E: StepEquations<N, Manifold = Vectors>, const N: usize> Stepper<E::System, N, E> {
    /// Each component's energy balance since the start, for a model made of components
    /// ([`Interconnected`]: an `Interconnection`, `Repeated`, or an attribute with
    /// `subsystems(...)`): energy stored, work of its own forces and inputs (a resistor's
    /// dissipation, a source's supply) and work through its ports. `Unsupported` where the
    /// step does not report its work or holds the junctions at several points of a step (the
    /// Galerkin rules); `NotStarted` before a start.
    ///
    /// ```
    /// use dirac_runtime::interconnection::{Interconnection, Junction};
    /// use dirac_runtime::{DiracSystem, Quadrature, Scalar, Stepper};
    /// use nalgebra::{SVector, vector};
    ///
    /// /// A capacitor, L = −q²/(2c).
    /// struct Capacitor;
    /// impl DiracSystem<1> for Capacitor {
    ///     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, _v: &SVector<D, 1>) -> D {
    ///         -q[0] * q[0] * 0.5
    ///     }
    ///     fn coordinate_name(&self, _i: usize) -> String { "q".into() }
    /// }
    /// /// An inductor with a series resistance: L = q̇²/2, F = −0.2 q̇ dq.
    /// struct Coil;
    /// impl DiracSystem<1> for Coil {
    ///     const FORCES: bool = true;
    ///     fn lagrangian<D: Scalar>(&self, _q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
    ///         v[0] * v[0] * 0.5
    ///     }
    ///     fn force<D: Scalar>(&self, _q: &SVector<D, 1>, v: &SVector<D, 1>, _t: f64, _u: &[D])
    ///         -> SVector<D, 1> {
    ///         SVector::from([v[0] * -0.2])
    ///     }
    ///     fn coordinate_name(&self, _i: usize) -> String { "q".into() }
    /// }
    /// let loop_ = Interconnection::new(
    ///     ("c", Capacitor),
    ///     ("coil", Coil),
    ///     [Junction::new("kcl").flow("c.q", 1.0).flow("coil.q", 1.0)],
    /// )?;
    /// let mut stepper = Stepper::new(loop_, Quadrature::midpoint(), 0.01)?;
    /// stepper.start_from_velocity(vector![1.0, -1.0], vector![0.0, 0.0])?;
    /// stepper.run(1000)?;
    /// let ledger = stepper.ledger()?;
    /// println!("{ledger}");
    /// let [c, coil] = &ledger.components[..] else { unreachable!() };
    /// assert!(c.energy < c.initial && coil.forces < 0.0); // the resistance took the charge's energy
    /// assert!(ledger.max_defect() < 1e-14 && ledger.net_port_work().abs() < 1e-14);
    /// # Ok::<(), dirac_runtime::DiracError>(())
    /// ```
    pub fn ledger<const K: usize, const C: usize>(&self) -> Result<Ledger, DiracError>
    where
        E::System: Interconnected<N, K, C>,
    {
        let work = self.work_by_coordinate()?;
        let through = work.constraints.ok_or_else(|| {
            DiracError::Unsupported(format!(
                "the work through the ports of {} with {}: the junctions are held at several \
                 points of a step, or the step is projected",
                E::NAME,
                self.equations.method()
            ))
        })?;
        let (Some(origin), Some(state)) = (self.origin, self.state) else {
            return Err(DiracError::NotStarted);
        };
        let v0 = self.velocity_at(origin.t, &origin.q, &origin.p, &origin.velocity, true)?;
        let v = self.v()?;
        let system = self.equations.system();
        let (initial, energy) = (
            system.energies(&origin.q, &v0),
            system.energies(&state.q, &v),
        );
        let (mut forces, mut ports) = ([0.0; K], [0.0; K]);
        for i in 0..N {
            let c = system.component_of(i);
            forces[c] += work.forces[i];
            ports[c] += through[i];
        }
        Ok(Ledger {
            components: (0..K)
                .map(|c| ComponentBalance {
                    name: system.component_name(c),
                    initial: initial[c],
                    energy: energy[c],
                    forces: forces[c],
                    ports: ports[c],
                })
                .collect(),
        })
    }
}
