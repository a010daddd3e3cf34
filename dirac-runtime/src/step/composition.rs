//! Symmetric compositions of the Störmer–Verlet step: `Φ_h = Φ_{γ_s h} ∘ … ∘ Φ_{γ_1 h}` with
//! `Σ γ_i = 1` and `γ_i = γ_{s+1−i}`.
//!
//! Each factor is a Störmer–Verlet step, the exact discrete flow of the discrete Lagrangian
//! `L_d = (h/2) [L(q_0, Δq/h) + L(q_1, Δq/h)]`, so a composition is variational and symplectic;
//! symmetric coefficients make it symmetric, so its order is even. The coefficients below are the
//! published ones (Yoshida 1990, Suzuki 1990, McLachlan 1995, Kahan & Li 1997, Sofroniou &
//! Spaletta 2005); each method's order is measured against a closed form in
//! `tests/suite/explicit.rs`. The middle coefficient is `1 − 2 Σ` of the others, so the
//! coefficients sum to one to round-off.

use crate::base::error::DiracError;

// The coefficients below keep the digits they were published with; each rounds to the nearest
// `f64` at compile time.

/// A symmetric composition of Störmer–Verlet steps.
///
/// ```
/// use dirac_runtime::Composition;
///
/// let jump = Composition::triple_jump();
/// assert_eq!((jump.order(), jump.stages()), (4, 3));
/// let sum: f64 = jump.coefficients().iter().sum();
/// assert!((sum - 1.0).abs() < 1e-15);
/// assert_eq!(Composition::of_order(8)?.name(), "Kahan–Li 8 (17 stages)");
/// # Ok::<(), dirac_runtime::DiracError>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Composition {
    name: &'static str,
    order: usize,
    coefficients: Vec<f64>,
}

/// The first half of McLachlan's 15-stage method of order 8 (its middle coefficient follows).
#[allow(clippy::excessive_precision)]
const MCLACHLAN_8: [f64; 7] = [
    0.741_670_364_350_612_953_448_227_80,
    -0.409_100_825_800_031_593_997_300_10,
    0.190_754_710_296_238_379_953_876_26,
    -0.573_862_471_116_082_266_656_387_73,
    0.299_064_181_303_655_923_844_463_54,
    0.334_624_918_245_298_183_784_957_98,
    0.315_293_092_396_766_596_632_056_66,
];

/// The first half of Kahan and Li's 9-stage method of order 6.
#[allow(clippy::excessive_precision)]
const KAHAN_LI_6: [f64; 4] = [
    0.392_161_444_007_314_139_279_250_56,
    0.332_599_136_789_359_438_599_748_64,
    -0.706_246_172_557_639_359_809_964_82,
    0.082_213_596_293_550_800_231_490_45,
];

/// The first half of Kahan and Li's 17-stage method of order 8.
#[allow(clippy::excessive_precision)]
const KAHAN_LI_8: [f64; 8] = [
    0.130_202_483_088_890_080_878_817_63,
    0.561_162_981_775_108_384_561_964_41,
    -0.389_474_962_644_847_286_408_078_60,
    0.158_841_906_555_155_600_896_210_75,
    -0.395_903_894_133_237_577_336_231_54,
    0.184_539_640_978_315_707_091_832_54,
    0.258_374_387_686_322_047_293_979_11,
    0.295_011_723_609_310_298_870_966_24,
];

/// The first half of Sofroniou and Spaletta's 35-stage method of order 10.
#[allow(clippy::excessive_precision)]
const SOFRONIOU_SPALETTA_10: [f64; 17] = [
    0.078_795_722_521_686_419_263_907_68,
    0.313_096_103_415_108_527_764_812_47,
    0.027_918_383_235_078_066_109_520_27,
    -0.229_592_841_593_907_094_151_213_40,
    0.130_962_061_077_164_863_174_656_86,
    -0.269_733_405_654_510_714_344_609_73,
    0.074_973_343_155_891_435_666_137_11,
    0.111_993_423_999_810_204_889_575_08,
    0.366_133_449_546_226_751_193_148_12,
    -0.399_105_630_136_035_897_878_629_81,
    0.103_087_398_527_471_077_315_802_77,
    0.411_430_873_955_890_237_820_704_12,
    -0.004_866_360_583_135_261_762_195_66,
    -0.392_033_353_708_639_906_448_081_94,
    0.051_942_502_962_449_647_037_182_90,
    0.050_665_090_759_924_496_335_874_34,
    0.049_674_370_639_729_879_054_568_80,
];

impl Composition {
    /// The symmetric composition whose first half is `half` (the middle coefficient makes the
    /// sum one).
    fn symmetric(name: &'static str, order: usize, half: &[f64]) -> Self {
        let middle = 1.0 - 2.0 * half.iter().sum::<f64>();
        let mut coefficients = half.to_vec();
        coefficients.push(middle);
        coefficients.extend(half.iter().rev());
        Self {
            name,
            order,
            coefficients,
        }
    }

    /// The Störmer–Verlet step itself: order 2, one gradient per step.
    pub fn verlet() -> Self {
        Self {
            name: "Störmer–Verlet",
            order: 2,
            coefficients: vec![1.0],
        }
    }

    /// Yoshida's triple jump, `γ_1 = γ_3 = 1/(2 − ∛2)`: order 4 in 3 stages.
    pub fn triple_jump() -> Self {
        let outer = 1.0 / (2.0 - 2f64.cbrt());
        Self::symmetric("triple jump", 4, &[outer])
    }

    /// Suzuki's fractal, `γ_1 = γ_2 = γ_4 = γ_5 = 1/(4 − ∛4)`: order 4 in 5 stages, with a
    /// smaller error constant than the triple jump.
    pub fn suzuki() -> Self {
        let outer = 1.0 / (4.0 - 4f64.cbrt());
        Self::symmetric("Suzuki", 4, &[outer, outer])
    }

    /// Kahan and Li's method of order 6 in 9 stages.
    pub fn kahan_li_6() -> Self {
        Self::symmetric("Kahan–Li 6 (9 stages)", 6, &KAHAN_LI_6)
    }

    /// McLachlan's method of order 8 in 15 stages.
    pub fn mclachlan_8() -> Self {
        Self::symmetric("McLachlan 8 (15 stages)", 8, &MCLACHLAN_8)
    }

    /// Kahan and Li's method of order 8 in 17 stages.
    pub fn kahan_li_8() -> Self {
        Self::symmetric("Kahan–Li 8 (17 stages)", 8, &KAHAN_LI_8)
    }

    /// Sofroniou and Spaletta's method of order 10 in 35 stages.
    pub fn sofroniou_spaletta_10() -> Self {
        Self::symmetric(
            "Sofroniou–Spaletta 10 (35 stages)",
            10,
            &SOFRONIOU_SPALETTA_10,
        )
    }

    /// The composition this library takes for `order` (2, 4, 6, 8 or 10): Störmer–Verlet,
    /// Suzuki, Kahan–Li 6, Kahan–Li 8, Sofroniou–Spaletta 10. Another order is
    /// `InvalidQuadrature`.
    pub fn of_order(order: usize) -> Result<Self, DiracError> {
        match order {
            2 => Ok(Self::verlet()),
            4 => Ok(Self::suzuki()),
            6 => Ok(Self::kahan_li_6()),
            8 => Ok(Self::kahan_li_8()),
            10 => Ok(Self::sofroniou_spaletta_10()),
            _ => Err(DiracError::InvalidQuadrature(format!(
                "no composition of order {order}: the compositions of Störmer–Verlet have \
                 orders 2, 4, 6, 8 and 10"
            ))),
        }
    }

    /// The method's name.
    pub fn name(&self) -> &'static str {
        self.name
    }

    /// The order of the method.
    pub fn order(&self) -> usize {
        self.order
    }

    /// The number of Störmer–Verlet steps in one step: the gradients of the potential one step
    /// evaluates (the last of a step is the first of the next).
    pub fn stages(&self) -> usize {
        self.coefficients.len()
    }

    /// The coefficients `γ_1, …, γ_s`: the fractions of the step each Störmer–Verlet step takes.
    pub fn coefficients(&self) -> &[f64] {
        &self.coefficients
    }
}
