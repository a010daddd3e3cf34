//! A block-bordered Jacobian, solved by its diagonal blocks and a Schur complement (see
//! [`Bordered`]).

use nalgebra::DMatrix;
use rayon::prelude::*;

use crate::base::error::DiracError;
use crate::base::float::largest;
use crate::base::runs::{Runs, in_runs};
use crate::solve::banded::Banded;
use crate::solve::jacobian::Jacobian;
use crate::solve::lu::{self, SingularPivot};

/// Entries per parallel task of a solver's passes over its vectors when the blocks are worked
/// on across threads: a copy or a norm of this many entries takes a few microseconds.
const VECTOR_GRAIN: usize = 1 << 14;

/// A block-bordered Jacobian, solved by its diagonal blocks and a Schur complement.
///
/// ```text
///     ⎡ J_1            E_1 ⎤        J_c   a block's own unknowns (filled per evaluation)
/// J = ⎢      ⋱          ⋮  ⎥        E_c   how the couplings μ enter block c's rows
///     ⎢          J_K   E_K ⎥        G_c   how block c's unknowns enter the coupling rows
///     ⎣ G_1  …   G_K    0  ⎦        (E_c and G_c on the couplings touching c)
/// ```
///
/// The borders are set when the Jacobian is built; the residual's closure fills each `J_c` and
/// may rewrite the borders of couplings whose coefficients change with the unknowns (a joint's
/// rows, see [`BlockMatrix`]).
///
/// `J (x, μ) = (r, s)` is solved by `z_c = J_c⁻¹ r_c`, `Y_c = J_c⁻¹ E_c`, the Schur complement
/// `S = Σ_c G_c Y_c`, `S μ = Σ_c G_c z_c − s`, and `x_c = z_c − Y_c μ`. Each block is factorised
/// on its own, so `K` blocks of size `n` cost `O(K n³)`; `S` is a band matrix whose width is the
/// largest spread of the couplings one block touches (numbered along a chain, a few), so it
/// costs `O(m b²)` for `m` couplings and half-width `b`. Factorising `S` with partial pivoting
/// needs every `J_c` regular on its own: a block singular alone (a coordinate that only the
/// couplings determine) is refused, naming its column.
///
/// ```
/// use dirac_runtime::jacobian::{Bordered, Jacobian};
/// // Two 1 × 1 blocks coupled by one row x₀ − x₁ (E = Gᵀ).
/// let mut j = Bordered::new(&[1, 1], &[vec![(0, 0, 1.0)], vec![(0, 0, -1.0)]], &[
///     vec![(0, 0, 1.0)],
///     vec![(0, 0, -1.0)],
/// ])?;
/// j.matrix()[0].own[(0, 0)] = 2.0;
/// j.matrix()[1].own[(0, 0)] = 4.0;
/// j.factorise(1e-13).unwrap();
/// // [[2, 0, 1], [0, 4, −1], [1, −1, 0]] (x₀, x₁, μ) = (3, 3, 0)
/// let mut b = [3.0, 3.0, 0.0];
/// j.solve(&mut b);
/// assert!((b[0] - 1.0).abs() < 1e-15 && (b[1] - 1.0).abs() < 1e-15 && (b[2] - 1.0).abs() < 1e-15);
/// # Ok::<(), dirac_runtime::DiracError>(())
/// ```
#[derive(Debug, Clone)]
pub struct Bordered {
    /// The diagonal blocks `J_c` and their borders, filled by the residual's closure.
    diagonal: Vec<BlockMatrix>,
    blocks: Vec<Block>,
    /// The number of couplings (the last unknowns and rows).
    couplings: usize,
    size: usize,
    schur: Banded,
    /// Blocks per parallel task (`usize::MAX`: one after another).
    grain: usize,
    /// The blocks each coupling touches, `(block, its row in the block's touching)`, coupling
    /// after coupling (`starts[j]..starts[j + 1]`), the blocks in order.
    touched: Vec<(usize, usize)>,
    starts: Vec<usize>,
}

/// Block `c` of a [`Bordered`] Jacobian as its residual's closure fills it: `J_c` and its
/// borders on the couplings that touch it (ascending).
#[derive(Debug, Clone)]
pub struct BlockMatrix {
    /// `J_c`: the block's rows × its unknowns (zeroed before each evaluation).
    pub own: DMatrix<f64>,
    /// `E_c`: the block's rows × the couplings touching it (kept between evaluations).
    pub e: DMatrix<f64>,
    /// `G_c`: the couplings touching it × the block's unknowns (kept between evaluations).
    pub g: DMatrix<f64>,
}

/// What a diagonal block keeps beside its matrix.
#[derive(Debug, Clone)]
struct Block {
    /// The first unknown (and row) of the block.
    offset: usize,
    /// The couplings that touch the block, ascending.
    touching: Vec<usize>,
    /// The borders `E_c`, `G_c` as built (restored with the block's shape).
    e: DMatrix<f64>,
    g: DMatrix<f64>,
    /// `J_c⁻¹ E_c` after factorising.
    y: DMatrix<f64>,
    /// `G_c J_c⁻¹ E_c`, its part of the Schur complement, after factorising.
    gy: DMatrix<f64>,
    pivots: Vec<usize>,
    scales: Vec<f64>,
}

impl Bordered {
    /// Blocks of `sizes` unknowns; `rows[c]` lists the entries `(row of block c, coupling,
    /// value)` of `E_c` and `columns[c]` the entries `(coupling, column of block c, value)` of
    /// `G_c`. The couplings are the unknowns after the blocks' (as many as the largest coupling
    /// named, plus one). `Err(Dimension)` where the lists are not one per block, an entry lies
    /// outside its block, or a coupling has no entry in any `E` or in any `G` (its Schur column
    /// or row would be zero); `Unsupported` where the Schur complement's band would not fit in
    /// memory (a coupling of blocks far apart in their order).
    pub fn new(
        sizes: &[usize],
        rows: &[Vec<(usize, usize, f64)>],
        columns: &[Vec<(usize, usize, f64)>],
    ) -> Result<Self, DiracError> {
        let invalid = |why: String| Err(DiracError::Dimension(why));
        if rows.len() != sizes.len() || columns.len() != sizes.len() {
            return invalid(format!(
                "{} blocks with {} lists of E entries and {} of G entries",
                sizes.len(),
                rows.len(),
                columns.len()
            ));
        }
        for (c, &n) in sizes.iter().enumerate() {
            let outside = |i: usize| i >= n;
            if rows[c].iter().any(|e| outside(e.0)) || columns[c].iter().any(|g| outside(g.1)) {
                return invalid(format!("an entry of block {c} outside its {n} unknowns"));
            }
        }
        let couplings = rows
            .iter()
            .flatten()
            .map(|e| e.1 + 1)
            .chain(columns.iter().flatten().map(|g| g.0 + 1))
            .max()
            .unwrap_or(0);
        let mut offset = 0;
        let mut spread = 0;
        let blocks: Vec<Block> = sizes
            .iter()
            .enumerate()
            .map(|(c, &n)| {
                let mut touching: Vec<usize> = rows[c]
                    .iter()
                    .map(|e| e.1)
                    .chain(columns[c].iter().map(|g| g.0))
                    .collect();
                touching.sort_unstable();
                touching.dedup();
                if let (Some(first), Some(last)) = (touching.first(), touching.last()) {
                    spread = spread.max(last - first);
                }
                let at = |coupling| touching.binary_search(&coupling).expect("listed");
                let mut e = DMatrix::zeros(n, touching.len());
                for &(i, j, v) in &rows[c] {
                    e[(i, at(j))] += v;
                }
                let mut g = DMatrix::zeros(touching.len(), n);
                for &(j, i, v) in &columns[c] {
                    g[(at(j), i)] += v;
                }
                let block = Block {
                    offset,
                    y: DMatrix::zeros(n, touching.len()),
                    gy: DMatrix::zeros(touching.len(), touching.len()),
                    touching,
                    e,
                    g,
                    pivots: vec![0; n],
                    scales: vec![0.0; n],
                };
                offset += n;
                block
            })
            .collect();
        // Every coupling needs entries in some E (its column) and some G (its row).
        let (mut in_e, mut in_g) = (vec![false; couplings], vec![false; couplings]);
        rows.iter().flatten().for_each(|e| in_e[e.1] = true);
        columns.iter().flatten().for_each(|g| in_g[g.0] = true);
        if let Some(j) = (0..couplings).find(|&j| !(in_e[j] && in_g[j])) {
            return invalid(format!(
                "coupling {j} has no entry in any block's {}: its Schur row or column would be \
                 zero",
                if in_e[j] { "G" } else { "E" }
            ));
        }
        let mut starts = vec![0; couplings + 1];
        for &j in blocks.iter().flat_map(|b| &b.touching) {
            starts[j + 1] += 1;
        }
        for j in 0..couplings {
            starts[j + 1] += starts[j];
        }
        let mut touched = vec![(0, 0); starts[couplings]];
        let mut next = starts.clone();
        for (c, block) in blocks.iter().enumerate() {
            for (a, &j) in block.touching.iter().enumerate() {
                touched[next[j]] = (c, a);
                next[j] += 1;
            }
        }
        Ok(Self {
            diagonal: blocks.iter().map(Block::matrix).collect(),
            blocks,
            touched,
            starts,
            couplings,
            size: offset + couplings,
            schur: Banded::within_memory(
                couplings,
                spread,
                spread,
                "the junctions' Schur complement",
            )?,
            grain: usize::MAX,
        })
    }

    /// Measures, factorises and solves the blocks, and forms the coupling rows, across rayon's
    /// threads in pieces of about `grain` blocks or couplings (`usize::MAX`, the default: one
    /// after another); the Schur complement's band is factorised and solved on one thread. The result
    /// is the same bit for bit.
    pub fn parallel(mut self, grain: usize) -> Self {
        self.grain = grain.max(1);
        self
    }

    /// Whether the blocks are worked on across threads.
    fn in_parallel(&self) -> bool {
        self.grain < self.blocks.len()
    }

    /// The half-width of the Schur complement's band.
    pub fn band(&self) -> usize {
        self.blocks
            .iter()
            .filter_map(|b| Some(b.touching.last()? - b.touching.first()?))
            .max()
            .unwrap_or(0)
    }

    /// Where the couplings' unknowns begin.
    fn first_coupling(&self) -> usize {
        self.size - self.couplings
    }

    /// The couplings touching block `c`, ascending: the columns of its `E_c` and rows of its
    /// `G_c`.
    pub fn touching(&self, c: usize) -> &[usize] {
        &self.blocks[c].touching
    }
}

impl Block {
    /// A zero `J_c` with the borders as built.
    fn matrix(&self) -> BlockMatrix {
        let n = self.pivots.len();
        BlockMatrix {
            own: DMatrix::zeros(n, n),
            e: self.e.clone(),
            g: self.g.clone(),
        }
    }
}

impl Jacobian for Bordered {
    type Matrix = Vec<BlockMatrix>;

    fn size(&self) -> usize {
        self.size
    }

    fn matrix(&mut self) -> &mut Vec<BlockMatrix> {
        &mut self.diagonal
    }

    fn clear(&mut self) {
        let zero = |j: &mut BlockMatrix| j.own.fill(0.0);
        if self.in_parallel() {
            let blocks = self.diagonal.par_iter_mut().with_min_len(self.grain);
            blocks.for_each(zero);
        } else {
            self.diagonal.iter_mut().for_each(zero);
        }
    }

    fn fits(&self, n: usize) -> bool {
        n == self.size
            && self.diagonal.len() == self.blocks.len()
            && self.diagonal.iter().zip(&self.blocks).all(|(j, b)| {
                j.own.shape() == (b.pivots.len(), b.pivots.len())
                    && j.e.shape() == b.e.shape()
                    && j.g.shape() == b.g.shape()
            })
    }

    fn restore(&mut self, _n: usize) {
        self.diagonal = self.blocks.iter().map(Block::matrix).collect();
    }

    fn norm(&mut self) -> f64 {
        // The largest row sum, NaN where a sum is (a NaN entry), as `row_sum_norm`.
        let most = |a: f64, b: f64| largest([a, b]);
        let block_rows = |(j, block): (&BlockMatrix, &Block)| {
            let n = j.own.nrows();
            let (a, e) = (j.own.as_slice(), j.e.as_slice());
            let rows = (0..n).map(|i| {
                let own: f64 = (0..n).map(|k| a[i + k * n].abs()).sum();
                own + (0..block.touching.len())
                    .map(|c| e[i + c * n].abs())
                    .sum::<f64>()
            });
            largest(rows)
        };
        // A coupling's row: its entries in the blocks it touches, block after block.
        let coupling_row = |j: usize| {
            let touched = &self.touched[self.starts[j]..self.starts[j + 1]];
            let entries = touched.iter().map(|&(c, a)| {
                let g = &self.diagonal[c].g;
                (0..g.ncols()).map(|k| g[(a, k)].abs()).sum::<f64>()
            });
            entries.sum::<f64>()
        };
        let pairs = || self.diagonal.iter().zip(&self.blocks);
        if self.in_parallel() {
            let blocks = self.diagonal.par_iter().zip(&self.blocks);
            let blocks = blocks.with_min_len(self.grain).map(block_rows);
            let couplings = (0..self.couplings).into_par_iter().with_min_len(self.grain);
            let (blocks, couplings) = rayon::join(
                || blocks.reduce(|| 0.0, most),
                || couplings.map(coupling_row).reduce(|| 0.0, most),
            );
            most(blocks, couplings)
        } else {
            let blocks = largest(pairs().map(block_rows));
            most(blocks, largest((0..self.couplings).map(coupling_row)))
        }
    }

    fn is_finite(&self) -> bool {
        let finite = |j: &BlockMatrix| {
            let entries = j.own.iter().chain(j.e.iter()).chain(j.g.iter());
            entries.copied().all(f64::is_finite)
        };
        if self.in_parallel() {
            let blocks = self.diagonal.par_iter().with_min_len(self.grain);
            blocks.all(finite)
        } else {
            self.diagonal.iter().all(finite)
        }
    }

    fn vector_grain(&self) -> usize {
        if self.in_parallel() {
            VECTOR_GRAIN
        } else {
            usize::MAX
        }
    }

    fn factorise(&mut self, tolerance: f64) -> Result<(), SingularPivot> {
        let factorise = |(matrix, block): (&mut BlockMatrix, &mut Block)| {
            let j = &mut matrix.own;
            lu::factorise(j, &mut block.pivots, &mut block.scales, tolerance).map_err(|p| {
                SingularPivot {
                    column: block.offset + p.column,
                    involved: p.involved.iter().map(|i| block.offset + i).collect(),
                }
            })?;
            block.y.copy_from(&matrix.e);
            let n = j.nrows();
            for column in block.y.as_mut_slice().chunks_exact_mut(n.max(1)) {
                lu::solve(j, &block.pivots, column);
            }
            // Its part of the Schur complement, G_c Y_c, without a temporary.
            let t = block.touching.len();
            for a in 0..t {
                for b in 0..t {
                    let mut entry = 0.0;
                    for i in 0..n {
                        entry += matrix.g[(a, i)] * block.y[(i, b)];
                    }
                    block.gy[(a, b)] = entry;
                }
            }
            Ok(())
        };
        // The first singular block (by column) whichever thread met it.
        let first = |a: Result<(), SingularPivot>, b: Result<(), SingularPivot>| match (a, b) {
            (Err(a), Err(b)) => Err(if a.column <= b.column { a } else { b }),
            (Err(e), Ok(())) | (Ok(()), Err(e)) => Err(e),
            (Ok(()), Ok(())) => Ok(()),
        };
        if self.in_parallel() {
            self.diagonal
                .par_iter_mut()
                .zip(self.blocks.par_iter_mut())
                .with_min_len(self.grain)
                .map(factorise)
                .reduce(|| Ok(()), first)?;
        } else {
            let pairs = self.diagonal.iter_mut().zip(self.blocks.iter_mut());
            pairs.map(factorise).try_for_each(|r| r)?;
        }
        // Σ_c G_c Y_c into the Schur complement, block after block.
        self.schur.clear();
        for block in &self.blocks {
            for (a, &row) in block.touching.iter().enumerate() {
                for (b, &column) in block.touching.iter().enumerate() {
                    self.schur.add(row, column, block.gy[(a, b)]);
                }
            }
        }
        let first = self.first_coupling();
        self.schur.factorise(tolerance).map_err(|p| SingularPivot {
            column: first + p.column,
            involved: p.involved.iter().map(|j| first + j).collect(),
        })
    }

    fn solve(&self, b: &mut [f64]) {
        let first = self.first_coupling();
        let (own, coupling) = b.split_at_mut(first);
        let runs = BlockRuns {
            diagonal: &self.diagonal,
            blocks: &self.blocks,
        };
        let nothing = |(), ()| ();
        let solve = |piece: BlockRuns<'_>, run: &mut [f64]| {
            piece.each(run, |j, block, z| lu::solve(&j.own, &block.pivots, z));
        };
        in_runs(runs, own, self.grain, &solve, &nothing);
        // s − Σ G_c z_c, negated: coupling by coupling, over the blocks it touches in order.
        let z = &*own;
        let row = |(j, value): (usize, &mut f64)| {
            for &(c, a) in &self.touched[self.starts[j]..self.starts[j + 1]] {
                let block = &self.blocks[c];
                let z = &z[block.offset..block.offset + block.y.nrows()];
                let g = self.diagonal[c].g.row(a);
                *value -= g.iter().zip(z).map(|(g, z)| g * z).sum::<f64>();
            }
            *value = -*value;
        };
        if self.grain < self.couplings {
            let rows = coupling.par_iter_mut().enumerate().with_min_len(self.grain);
            rows.for_each(row);
        } else {
            coupling.iter_mut().enumerate().for_each(row);
        }
        self.schur.solve(coupling);
        // x_c = z_c − Y_c μ.
        let mu = &*coupling;
        let back = |piece: BlockRuns<'_>, run: &mut [f64]| {
            piece.each(run, |_, block, z| {
                for (a, &c) in block.touching.iter().enumerate() {
                    for (i, zi) in z.iter_mut().enumerate() {
                        *zi -= block.y[(i, a)] * mu[c];
                    }
                }
            });
        };
        in_runs(runs, own, self.grain, &back, &nothing);
    }
}

/// Blocks with their matrices, each owning its rows of a vector.
#[derive(Clone, Copy)]
struct BlockRuns<'a> {
    diagonal: &'a [BlockMatrix],
    blocks: &'a [Block],
}

impl Runs for BlockRuns<'_> {
    fn count(&self) -> usize {
        self.blocks.len()
    }

    fn start(&self, i: usize) -> usize {
        self.blocks[i].offset
    }

    fn halve(self, mid: usize) -> (Self, Self) {
        let (diagonal, blocks) = (self.diagonal.split_at(mid), self.blocks.split_at(mid));
        (
            Self {
                diagonal: diagonal.0,
                blocks: blocks.0,
            },
            Self {
                diagonal: diagonal.1,
                blocks: blocks.1,
            },
        )
    }
}

impl BlockRuns<'_> {
    /// `f(J_c, block, its rows of run)` for each block, `run` beginning at the first one's rows.
    fn each(self, run: &mut [f64], f: impl Fn(&BlockMatrix, &Block, &mut [f64])) {
        let Some(start) = self.blocks.first().map(|b| b.offset) else {
            return;
        };
        for (j, block) in self.diagonal.iter().zip(self.blocks) {
            let at = block.offset - start;
            f(j, block, &mut run[at..at + j.own.nrows()]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solve::jacobian::Dense;
    use nalgebra::DVector;

    /// A chain of `k` blocks of `n` unknowns, coupling `i` joining the last unknown of block `i`
    /// to the first of block `i + 1` (`E = σ Gᵀ`), with nonsymmetric blocks.
    fn chain(k: usize, n: usize) -> (Bordered, Dense) {
        let mut rows = vec![Vec::new(); k];
        let mut columns = vec![Vec::new(); k];
        for i in 0..k - 1 {
            rows[i].push((n - 1, i, 0.5));
            columns[i].push((i, n - 1, 1.0));
            rows[i + 1].push((0, i, -0.5));
            columns[i + 1].push((i, 0, -1.0));
        }
        let mut bordered = Bordered::new(&vec![n; k], &rows, &columns).unwrap();
        let size = bordered.size();
        let mut dense = Dense::new(size);
        for (c, j) in bordered.matrix().iter_mut().enumerate() {
            let j = &mut j.own;
            for r in 0..n {
                for s in 0..n {
                    let v = ((3 * c + 5 * r + 7 * s) % 11) as f64 - 5.0
                        + if r == s { 9.0 } else { 0.0 };
                    j[(r, s)] = v;
                    dense.matrix()[(c * n + r, c * n + s)] = v;
                }
            }
        }
        for (c, (rows, columns)) in rows.iter().zip(&columns).enumerate() {
            for &(i, j, v) in rows {
                dense.matrix()[(c * n + i, k * n + j)] = v;
            }
            for &(j, i, v) in columns {
                dense.matrix()[(k * n + j, c * n + i)] = v;
            }
        }
        (bordered, dense)
    }

    /// Both matrices factorised and solved for `b_i = sin i`: their solutions.
    fn solutions(a: &mut impl Jacobian, b: &mut impl Jacobian) -> (DVector<f64>, DVector<f64>) {
        a.factorise(1e-13).unwrap();
        b.factorise(1e-13).unwrap();
        let rhs = DVector::from_fn(a.size(), |i, _| (i as f64).sin());
        let (mut x, mut y) = (rhs.clone(), rhs);
        a.solve(x.as_mut_slice());
        b.solve(y.as_mut_slice());
        (x, y)
    }

    #[test]
    fn solves_and_measures_as_the_dense_matrix() {
        for (k, n) in [(2, 1), (5, 3), (12, 2)] {
            let (mut bordered, mut dense) = chain(k, n);
            assert_eq!(bordered.norm(), dense.norm());
            assert_eq!(bordered.band(), usize::from(k > 2));
            let (x, y) = solutions(&mut bordered, &mut dense);
            assert!((&x - &y).amax() < 1e-13 * y.amax(), "k {k}, n {n}");
        }
    }

    #[test]
    fn across_threads_the_same_bit_for_bit() {
        let (mut one, _) = chain(40, 3);
        let mut many = one.clone().parallel(1);
        assert_eq!(one.norm(), many.norm());
        assert!(many.is_finite());
        let (x, y) = solutions(&mut one, &mut many);
        assert_eq!(x, y);
    }

    #[test]
    fn malformed_borders_are_refused() {
        let one = vec![(0, 0, 1.0)];
        let twice = [one.clone(), one.clone()];
        assert!(Bordered::new(&[1, 1], std::slice::from_ref(&one), &twice).is_err());
        // A row index outside its block; a coupling without a G entry.
        assert!(Bordered::new(&[1], &[vec![(1, 0, 1.0)]], std::slice::from_ref(&one)).is_err());
        assert!(Bordered::new(&[1], std::slice::from_ref(&one), &[Vec::new()]).is_err());
        assert!(
            Bordered::new(&[1], std::slice::from_ref(&one), std::slice::from_ref(&one)).is_ok()
        );
    }

    #[test]
    fn a_block_singular_alone_names_its_column() {
        let (mut bordered, _) = chain(3, 2);
        bordered.matrix()[1].own.fill(0.0);
        assert_eq!(bordered.factorise(1e-13).unwrap_err().column, 2);
    }
}
