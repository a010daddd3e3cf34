//! The predictor of a step's unknowns: the last accepted solutions extrapolated one step ahead.
//!
//! A step's unknowns (the path's points in the chart at `q_k`, the multipliers) are smooth
//! functions of the time the step starts at, sampled every `h`. The polynomial through the last
//! `m` of them, evaluated one step ahead, is `O(h^m)` off their own size: the last solution
//! alone `O(h)`, the line through two `O(h²)`, the parabola through three `O(h³)`, the cubic
//! through four (`4x_k − 6x_{k−1} + 4x_{k−2} − x_{k−3}`) `O(h⁴)`. On the double pendulum at
//! h = 0.01 Newton's method takes 2.97 evaluations per step from the cubic, 3.06 from the
//! parabola and 3.22 from the line (1 000 steps); its coefficients amplify the solutions'
//! round-off by `√69 ≈ 8`, far below any tolerance. After a start or a change of inputs the
//! history begins again, and where the chart of the next step does not continue those of the
//! history (a unit vector whose chart frame changes branch).
//!
//! Constraint multipliers whose impulse a step shares between its two ends (one-forms or
//! junctions at the midpoint: `σ μ_k` on the start's equation, `(1 − σ) μ_k` in the end
//! momentum) are not smooth: the impulse at node `k` is `ν_k = (1 − σ) μ_{k−1} + σ μ_k`, and
//! `ν`, not `μ`, follows the motion. With `σ = ½`, `μ_k = 2 ν_k − μ_{k−1}` carries a mode
//! `(−1)^k` the start leaves (the first node takes half a step's impulse); where the impulse
//! changes fast it is large against the steps' changes, and extrapolating the `μ` mispredicts
//! it (a body and a flywheel joined by a shaft, by parts: 3 Newton evaluations a step where the
//! one model takes 2). For those the history holds the `ν`
//! ([`share_impulses`](Predictor::share_impulses)) and the prediction of `μ` follows from the
//! extrapolated `ν` and the last `μ`: the modular step's junctions. (A model's own one-forms
//! at the midpoint are predicted as they stand: on the knife edge, whose multiplier alternates
//! too, predicting its node impulses left Newton's 3.00 evaluations a step unchanged, as
//! holding the one-form at the step's end does.)

use std::ops::Range;

use nalgebra::DVector;

/// The last accepted solutions, newest first, and their extrapolation.
#[derive(Debug, Clone)]
pub(crate) struct Predictor {
    /// Up to four solutions, newest first; the buffers rotate, nothing is allocated per step.
    solutions: [DVector<f64>; 4],
    /// How many of `solutions` hold accepted steps of the current history.
    count: usize,
    /// The next step is predicted afresh (see [`detach`](Self::detach)).
    detached: bool,
    extrapolated: DVector<f64>,
    /// The multipliers whose impulse is shared between a step's ends, and the share `σ` on the
    /// start (see the [module](self)).
    shared: Option<(Range<usize>, f64)>,
    /// The last accepted solution as solved, kept once node impulses have been shared in the
    /// history (`last_kept`); until then the newest solution is it.
    last: DVector<f64>,
    last_kept: bool,
}

impl Predictor {
    /// An empty history for `n` unknowns.
    pub fn new(n: usize) -> Self {
        Self {
            solutions: std::array::from_fn(|_| DVector::zeros(n)),
            count: 0,
            detached: false,
            extrapolated: DVector::zeros(n),
            shared: None,
            last: DVector::zeros(n),
            last_kept: false,
        }
    }

    /// Extrapolates the impulses at the steps' nodes, `ν_k = (1 − σ) μ_{k−1} + σ μ_k`, of the
    /// multipliers `μ` in `range` (their share `σ` on the step's start), and predicts the next
    /// `μ` from them (see the [module](self)); `None`, or `σ = 1`, extrapolates the `μ`. Kept
    /// across [`clear`](Self::clear)s of the same size.
    pub fn share_impulses(&mut self, shared: Option<(Range<usize>, f64)>) {
        self.shared = shared.filter(|(range, share)| {
            !range.is_empty() && range.end <= self.last.len() && *share > 0.0 && *share < 1.0
        });
        if self.shared.is_some() && !self.last_kept {
            // Until now the newest solution was the last one as solved (none after a start).
            if self.count > 0 {
                let [newest, ..] = &self.solutions;
                self.last.copy_from(newest);
            } else {
                self.last.fill(0.0);
            }
            self.last_kept = true;
        }
    }

    /// Forgets every solution (a start, or unknowns of another size).
    pub fn clear(&mut self, n: usize) {
        if self.extrapolated.len() != n {
            *self = Self::new(n);
        }
        self.last.fill(0.0);
        self.last_kept = false;
        self.count = 0;
        self.detached = false;
    }

    /// Keeps only the last solution: the next step follows a change the history did not see.
    pub fn restart(&mut self) {
        self.count = self.count.min(1);
    }

    /// Keeps the last solution (for its step's dense output) but predicts the next step afresh,
    /// and begins the history again from it: the next step's unknowns are coordinates that the
    /// solutions so far do not continue (a chart that changed branch).
    pub fn detach(&mut self) {
        self.detached = true;
    }

    /// Records an accepted step's solution.
    #[inline(always)]
    pub fn record(&mut self, x: &DVector<f64>) {
        if x.len() != self.extrapolated.len() {
            self.clear(x.len());
        }
        self.solutions.rotate_right(1);
        self.solutions[0].copy_from_slice(x.as_slice());
        if let Some((range, share)) = &self.shared {
            // The multipliers before the first step of a history are zero (a start).
            for i in range.clone() {
                self.solutions[0][i] = (1.0 - share) * self.last[i] + share * x[i];
            }
            self.last_kept = true;
        }
        if self.last_kept {
            self.last.copy_from_slice(x.as_slice());
        }
        self.count = if self.detached {
            1
        } else {
            (self.count + 1).min(4)
        };
        self.detached = false;
    }

    /// The last accepted solution.
    pub fn last(&self) -> Option<&DVector<f64>> {
        let last = match self.last_kept {
            true => &self.last,
            false => &self.solutions[0],
        };
        (self.count > 0).then_some(last)
    }

    /// The prediction for the next step (none before the first accepted step).
    #[inline(always)]
    pub fn predict(&mut self) -> Option<&DVector<f64>> {
        if self.detached {
            return None;
        }
        let [a, b, c, d] = &self.solutions;
        let (a, b, c, d) = (a.as_slice(), b.as_slice(), c.as_slice(), d.as_slice());
        let next = self.extrapolated.as_mut_slice();
        // Element by element on the slices (the same operations, in the same order, as the
        // polynomial's weights applied vector by vector).
        match self.count {
            0 => return None,
            1 => next.copy_from_slice(a),
            2 => {
                for (e, (a, b)) in next.iter_mut().zip(a.iter().zip(b)) {
                    *e = 2.0 * a - b;
                }
            }
            3 => {
                for (e, ((a, b), c)) in next.iter_mut().zip(a.iter().zip(b).zip(c)) {
                    *e = (c + 3.0 * a) - 3.0 * b;
                }
            }
            _ => {
                for (e, (((a, b), c), d)) in next.iter_mut().zip(a.iter().zip(b).zip(c).zip(d)) {
                    *e = ((4.0 * a - 6.0 * b) + 4.0 * c) - d;
                }
            }
        }
        if let Some((range, share)) = &self.shared {
            for i in range.clone() {
                self.extrapolated[i] =
                    (self.extrapolated[i] - (1.0 - share) * self.last[i]) / share;
            }
        }
        Some(&self.extrapolated)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The cubic through four samples of a cubic continues it exactly; with fewer samples the
    /// prediction is the parabola, the line or the last value.
    #[test]
    fn extrapolates_polynomials_of_the_history_degree() {
        let f = |t: f64| DVector::from_vec(vec![1.0 + 2.0 * t - 0.5 * t * t, -t * t * t]);
        let quadratic = |t: f64| DVector::from_vec(vec![1.0 + 2.0 * t - 0.5 * t * t, -t * t]);
        let mut predictor = Predictor::new(2);
        assert!(predictor.predict().is_none());
        predictor.record(&f(0.0));
        assert_eq!(predictor.predict().unwrap(), &f(0.0));
        predictor.record(&f(1.0));
        // The line through t = 0, 1 at t = 2.
        assert_eq!(predictor.predict().unwrap(), &(f(1.0) * 2.0 - f(0.0)));
        predictor.record(&f(2.0));
        // The parabola through t = 0, 1, 2 at t = 3.
        let parabola = f(2.0) * 3.0 - f(1.0) * 3.0 + f(0.0);
        assert!((predictor.predict().unwrap() - parabola).amax() < 1e-14);
        predictor.record(&f(3.0));
        assert!((predictor.predict().unwrap() - f(4.0)).amax() < 1e-13);
        predictor.record(&f(4.0));
        assert!((predictor.predict().unwrap() - f(5.0)).amax() < 1e-13);
        // A parabola is continued exactly from three samples.
        let mut parabolic = Predictor::new(2);
        for t in [0.0, 1.0, 2.0] {
            parabolic.record(&quadratic(t));
        }
        assert!((parabolic.predict().unwrap() - quadratic(3.0)).amax() < 1e-14);
        predictor.restart();
        assert_eq!(predictor.predict().unwrap(), &f(4.0));
        assert_eq!(predictor.last(), Some(&f(4.0)));
        // Detached: no prediction, the last solution kept, the history begun again from the
        // next one.
        predictor.detach();
        assert!(predictor.predict().is_none());
        assert_eq!(predictor.last(), Some(&f(4.0)));
        predictor.record(&f(5.0));
        assert_eq!(predictor.predict().unwrap(), &f(5.0));
        predictor.clear(3);
        assert!(predictor.predict().is_none() && predictor.last().is_none());
    }

    /// Multipliers that alternate about smooth node impulses (`μ_k = 2ν_k − μ_{k−1}` with
    /// `ν` a line and `μ_{−1} = 0`) are predicted exactly from the line through the `ν`.
    #[test]
    fn shared_impulses_predict_an_alternating_multiplier() {
        let nu = |k: f64| 1.0 + 0.1 * k;
        let mut mu = vec![2.0 * nu(0.0)];
        for k in 1..6 {
            mu.push(2.0 * nu(k as f64) - mu[k - 1]);
        }
        let mut predictor = Predictor::new(2);
        predictor.share_impulses(Some((1..2, 0.5)));
        for (k, &m) in mu.iter().enumerate().take(5) {
            predictor.record(&DVector::from_vec(vec![k as f64, m]));
        }
        assert_eq!(predictor.last().unwrap()[1], mu[4]);
        let predicted = predictor.predict().unwrap();
        assert!(
            (predicted[1] - mu[5]).abs() < 1e-13,
            "{} against {}",
            predicted[1],
            mu[5]
        );
        // Switched on after a history of plain solutions, the last one stays the last solution
        // as solved, and the next step's impulse is read from it.
        let mut late = Predictor::new(2);
        late.record(&DVector::from_vec(vec![0.0, mu[0]]));
        late.share_impulses(Some((1..2, 0.5)));
        assert_eq!(late.last().unwrap()[1], mu[0]);
        late.record(&DVector::from_vec(vec![1.0, mu[1]]));
        assert_eq!(late.last().unwrap()[1], mu[1]);
        assert_eq!(late.solutions[0][1], 0.5 * mu[0] + 0.5 * mu[1]);
        // Switched off again, the last solution is still the one as solved, not the impulse.
        late.share_impulses(None);
        assert_eq!(late.last().unwrap()[1], mu[1]);
        late.record(&DVector::from_vec(vec![2.0, mu[2]]));
        assert_eq!(late.last().unwrap()[1], mu[2]);
        // Extrapolated as it stands, the alternation is missed.
        let mut plain = Predictor::new(2);
        for (k, &m) in mu.iter().enumerate().take(5) {
            plain.record(&DVector::from_vec(vec![k as f64, m]));
        }
        assert!((plain.predict().unwrap()[1] - mu[5]).abs() > 0.1);
    }
}
