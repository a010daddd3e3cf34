//! Events: a user function `g(t, q, v)` whose sign changes are located inside the steps of a run
//! by root finding on the [dense output](crate::step::dense_output).
//!
//! After each step the run evaluates `g` at the step's end. A sign change across the step (in
//! the event's [`Direction`]) is located by the Illinois variant of regula falsi on
//! `θ ↦ g(dense output at θ)`, to the last bits of `θ`: the crossing's time is as accurate as the
//! dense output, not the step. Two crossings inside one step cancel and are not seen; a step
//! shorter than the time between crossings sees every one.

use std::cell::RefCell;
use std::rc::Rc;

use crate::base::error::DiracError;
use crate::space::manifold::{Manifold, Vectors};
use crate::step::dense_output::Sample;

/// Which sign changes of an event function count.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Direction {
    /// From negative to positive or from positive to negative.
    #[default]
    Either,
    /// From negative to zero or positive.
    Rising,
    /// From positive to zero or negative.
    Falling,
}

/// The user function of an event, shared by the event's clones.
type EventFunction<'a, const N: usize, M> = Rc<
    RefCell<
        dyn FnMut(f64, &<M as Manifold<N>>::Point<f64>, &<M as Manifold<N>>::Tangent<f64>) -> f64
            + 'a,
    >,
>;

/// An event of a [`Run`](crate::Run): a function `g(t, q, v)` whose sign changes are located
/// inside the steps, optionally ending the run at the first one. On Rⁿ, with the dimension
/// named, `Event::<N>::new`, the closure's argument types are inferred.
///
/// ```
/// use dirac_runtime::{DiracSystem, Event, Quadrature, Run, Scalar, Status, Stepper};
/// use nalgebra::{SVector, vector};
/// /// A ball thrown up: L = v²/2 − g q.
/// struct Ball;
/// impl DiracSystem<1> for Ball {
///     fn lagrangian<D: Scalar>(&self, q: &SVector<D, 1>, v: &SVector<D, 1>) -> D {
///         v[0] * v[0] * 0.5 - q[0] * 9.81
///     }
/// }
/// let mut stepper = Stepper::new(Ball, Quadrature::midpoint(), 0.01)?;
/// stepper.start_from_velocity(vector![1.0], vector![5.0])?;
/// let floor = Event::<1>::new("floor", |_t, q, _v| q[0]).falling().terminal();
/// let solution = stepper.solve(Run::until(10.0).event(floor.clone()))?;
/// assert_eq!(solution.status, Status::Event(0));
/// // 1 + 5t − 9.81 t²/2 = 0: the midpoint rule is exact for a constant force.
/// let exact = (5.0 + (25.0_f64 + 2.0 * 9.81).sqrt()) / 9.81;
/// assert!((solution.events[0].sample.t - exact).abs() < 1e-12);
/// // An event is cloned into each run that looks for it (the clones share its function).
/// stepper.start_from_velocity(vector![1.0], vector![5.0])?;
/// let again = stepper.solve(Run::until(10.0).event(floor.clone()))?;
/// assert_eq!(again.events[0].sample.t, solution.events[0].sample.t);
/// # Ok::<(), dirac_runtime::DiracError>(())
/// ```
pub struct Event<'a, const N: usize, M: Manifold<N> = Vectors> {
    name: String,
    function: EventFunction<'a, N, M>,
    direction: Direction,
    terminal: bool,
}

/// A clone looks for the same sign changes with the same function, which it shares: a closure
/// that keeps state keeps one state for the event and its clones.
impl<const N: usize, M: Manifold<N>> Clone for Event<'_, N, M> {
    fn clone(&self) -> Self {
        Self {
            name: self.name.clone(),
            function: Rc::clone(&self.function),
            direction: self.direction,
            terminal: self.terminal,
        }
    }
}

impl<const N: usize, M: Manifold<N>> std::fmt::Debug for Event<'_, N, M> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Event")
            .field("name", &self.name)
            .field("direction", &self.direction)
            .field("terminal", &self.terminal)
            .finish_non_exhaustive()
    }
}

impl<'a, const N: usize, M: Manifold<N>> Event<'a, N, M> {
    /// The event called `name` whose function is `g(t, q, v)`; every sign change counts and the
    /// run goes on after it.
    pub fn new(
        name: impl Into<String>,
        function: impl FnMut(f64, &M::Point<f64>, &M::Tangent<f64>) -> f64 + 'a,
    ) -> Self {
        Self {
            name: name.into(),
            function: Rc::new(RefCell::new(function)),
            direction: Direction::Either,
            terminal: false,
        }
    }

    /// Counts only the sign changes from negative to positive.
    pub fn rising(self) -> Self {
        Self {
            direction: Direction::Rising,
            ..self
        }
    }

    /// Counts only the sign changes from positive to negative.
    pub fn falling(self) -> Self {
        Self {
            direction: Direction::Falling,
            ..self
        }
    }

    /// Ends the run at the end of the step where the event is first located.
    pub fn terminal(self) -> Self {
        Self {
            terminal: true,
            ..self
        }
    }

    /// The event's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Whether the event ends the run.
    pub fn is_terminal(&self) -> bool {
        self.terminal
    }

    /// `g` at `sample`; an error when it is not finite.
    pub(crate) fn value(&mut self, sample: &Sample<N, M>) -> Result<f64, DiracError> {
        let g = (self.function.borrow_mut())(sample.t, &sample.q, &sample.v);
        if g.is_finite() {
            Ok(g)
        } else {
            Err(DiracError::NonFinite {
                what: format!("event {} at t = {}", self.name, sample.t),
                value: g,
            })
        }
    }

    /// The direction of the sign change from `before` to `after`, if it counts.
    pub(crate) fn crossing(&self, before: f64, after: f64) -> Option<Direction> {
        let rising = before < 0.0 && after >= 0.0;
        let falling = before > 0.0 && after <= 0.0;
        match self.direction {
            Direction::Rising | Direction::Either if rising => Some(Direction::Rising),
            Direction::Falling | Direction::Either if falling => Some(Direction::Falling),
            _ => None,
        }
    }
}

/// A located sign change of an event.
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
pub struct Crossing<const N: usize, M: Manifold<N> = Vectors> {
    /// Index of the event in the run (in the order the events were added).
    pub event: usize,
    /// The event's name.
    pub name: String,
    /// Which way `g` changed sign.
    pub direction: Direction,
    /// The solution at the crossing (dense output).
    pub sample: Sample<N, M>,
}

/// The root in `[0, 1]` of `g`, with `g(0) = g0` and `g(1) = g1` of opposite signs (or `g1 = 0`):
/// the end of the [`illinois`] bracket where `|g|` is smaller.
pub(crate) fn locate(
    g: impl FnMut(f64) -> Result<f64, DiracError>,
    g0: f64,
    g1: f64,
) -> Result<f64, DiracError> {
    let Bracket { a, ga, b, gb } = illinois(g, g0, g1)?;
    Ok(if ga.abs() < gb.abs() { a } else { b })
}

/// A bracket `[a, b]` of a root and the values kept at its ends (the Illinois rule halves them).
pub(crate) struct Bracket {
    pub a: f64,
    pub ga: f64,
    pub b: f64,
    pub gb: f64,
}

/// The bracket in `[0, 1]` around the root of `g`, with `g(0) = g0` and `g(1) = g1` of opposite
/// signs (or `g1 = 0`), closed by the Illinois variant of regula falsi to 4 ulps or to a point
/// where `g` vanishes (then `b`, with `gb = 0`). The end `b` keeps the sign of `g1`: every point
/// `g` was evaluated at where it has that sign, or vanishes, became `b` in its turn.
pub(crate) fn illinois(
    mut g: impl FnMut(f64) -> Result<f64, DiracError>,
    g0: f64,
    g1: f64,
) -> Result<Bracket, DiracError> {
    let (mut a, mut ga, mut b, mut gb) = (0.0, g0, 1.0, g1);
    if gb == 0.0 {
        return Ok(Bracket { a, ga, b, gb });
    }
    // Which end was kept last (−1: a, +1: b): the Illinois rule halves a value kept twice.
    let mut kept = 0;
    for _ in 0..200 {
        if b - a <= 4.0 * f64::EPSILON {
            break;
        }
        let mut c = (a * gb - b * ga) / (gb - ga);
        if !(c > a && c < b) {
            c = 0.5 * (a + b);
        }
        let gc = g(c)?;
        if gc == 0.0 {
            return Ok(Bracket {
                a,
                ga,
                b: c,
                gb: 0.0,
            });
        }
        if gc.signum() == gb.signum() {
            (b, gb) = (c, gc);
            if kept == -1 {
                ga *= 0.5;
            }
            kept = -1;
        } else {
            (a, ga) = (c, gc);
            if kept == 1 {
                gb *= 0.5;
            }
            kept = 1;
        }
    }
    Ok(Bracket { a, ga, b, gb })
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::SVector;

    #[test]
    fn locates_a_root_to_round_off() {
        let root = locate(|x| Ok(x.powi(3) - 0.2), -0.2, 0.8).unwrap();
        assert!((root - 0.2_f64.cbrt()).abs() < 1e-15);
        // A steep function that regula falsi alone would approach from one side only.
        let steep = |x: f64| (20.0 * (x - 0.9)).exp() - 1.0;
        let root = locate(|x| Ok(steep(x)), steep(0.0), steep(1.0)).unwrap();
        assert!((root - 0.9).abs() < 1e-15);
    }

    #[test]
    fn directions_count_only_their_sign_changes() {
        let g = |_t: f64, q: &SVector<f64, 1>, _v: &SVector<f64, 1>| q[0];
        let either = Event::<1>::new("x", g);
        assert_eq!(either.crossing(-1.0, 1.0), Some(Direction::Rising));
        assert_eq!(either.crossing(1.0, 0.0), Some(Direction::Falling));
        assert_eq!(either.crossing(0.0, 1.0), None);
        let rising = Event::<1>::new("x", g).rising();
        assert_eq!(rising.crossing(1.0, -1.0), None);
        assert_eq!(rising.crossing(-1.0, 0.0), Some(Direction::Rising));
        let falling = Event::<1>::new("x", g).falling();
        assert_eq!(falling.crossing(-1.0, 1.0), None);
    }
}
