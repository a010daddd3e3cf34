//! The performance limit for the 3D pendulum: Lee, Leok and McClamroch's Lie group variational
//! integrator (2005) written by hand, Newton on the Cayley parameter `f` of the relative attitude
//! `F = (I + f̂)(I − f̂)⁻¹`, with analytic derivatives and the same Newton solver as the
//! generated stepper.
//!
//! With `J_d = ½ tr(J) I − J`, the body momentum `Π` and the gravity torque
//! `M(R) = m g (Rᵀe₃) × ρ`, a step solves `h S(Π_k + (h/2) M_k) = F J_d − J_d Fᵀ`, which for the
//! Cayley parameter reads `φ(f) = g + g × f + (g·f) f − 2 J f = 0` with `g = h (Π_k + (h/2)M_k)`,
//! then `R_{k+1} = R_k F` and `Π_{k+1} = Fᵀ (Π_k + (h/2) M_k) + (h/2) M_{k+1}`.

use dirac::nalgebra::{DVector, Matrix3, Vector3};
use dirac::{Newton, NewtonOptions, rotation::hat};

use super::rigid_body::HeavyTop;

/// The hand-written integrator's state and workspace.
pub struct HandLgvi {
    pub j: Matrix3<f64>,
    pub m: f64,
    pub g: f64,
    pub rho: Vector3<f64>,
    pub h: f64,
    pub r: Matrix3<f64>,
    pub pi: Vector3<f64>,
    /// The last step's Cayley parameter: the next step's predictor.
    f: Vector3<f64>,
    newton: Newton,
    x: DVector<f64>,
}

impl HandLgvi {
    /// Starts `body` at attitude `r0` with body angular velocity `omega0`.
    pub fn new(body: &HeavyTop, h: f64, r0: Matrix3<f64>, omega0: Vector3<f64>) -> Self {
        let j = Matrix3::from_fn(|a, b| body.j[a][b]);
        Self {
            j,
            m: body.m,
            g: body.g,
            rho: Vector3::from(body.rho),
            h,
            r: r0,
            pi: j * omega0,
            f: omega0 * (0.5 * h),
            newton: Newton::new(3, NewtonOptions::default()).expect("the default options"),
            x: DVector::zeros(3),
        }
    }

    /// The gravity torque in body axes at attitude `r`.
    fn torque(&self, r: &Matrix3<f64>) -> Vector3<f64> {
        (r.transpose() * Vector3::z()).cross(&self.rho) * (self.m * self.g)
    }

    /// One step.
    pub fn step(&mut self) -> Result<(), dirac::NewtonFailure> {
        let (h, j) = (self.h, self.j);
        let impulse = self.pi + self.torque(&self.r) * (0.5 * h);
        let g = impulse * h;
        self.x.copy_from_slice(self.f.as_slice());
        self.newton.solve(&mut self.x, |x, residual, jacobian| {
            let f = Vector3::new(x[0], x[1], x[2]);
            let dot = g.dot(&f);
            let phi = g + g.cross(&f) + f * dot - j * f * 2.0;
            residual.copy_from_slice(phi.as_slice());
            if let Some(jacobian) = jacobian {
                let d = hat(&g) + Matrix3::identity() * dot + f * g.transpose() - j * 2.0;
                jacobian.copy_from(&d);
            }
            g.amax().max((j * f).amax())
        })?;
        let f = Vector3::new(self.x[0], self.x[1], self.x[2]);
        let k = hat(&f);
        let relative = (Matrix3::identity() + k)
            * (Matrix3::identity() - k)
                .try_inverse()
                .ok_or(dirac::NewtonFailure::NonFinite)?;
        self.r *= relative;
        self.pi = relative.transpose() * impulse + self.torque(&self.r) * (0.5 * h);
        self.f = f;
        Ok(())
    }
}
