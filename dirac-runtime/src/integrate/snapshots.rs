//! Snapshots of a field in a compact binary file, and their reader: every node's value at the
//! times chosen, as raw little-endian `f64`s after a short header. A snapshot of `N` nodes and
//! `C` components takes `8 (1 + N C)` bytes and reads back bit for bit (a CSV takes about three
//! times that and rounds).
//!
//! Layout, all little-endian: the magic `DIRACSNP` (8 bytes), the format's version (`u32`, 1),
//! the number of components `C` (`u32`), the number of nodes `N` (`u64`), the nodes' positions
//! (`N` × `f64`); then each snapshot: its time `t` (`f64`) and `u` node after node, each node's
//! components in order (`N C` × `f64`).

use std::io::{Read, Write};

use nalgebra::SVector;

use crate::base::error::DiracError;
use crate::model::density::SeparableDensity;
use crate::step::field::Field;

/// The file's first eight bytes.
const MAGIC: &[u8; 8] = b"DIRACSNP";
/// The layout's version.
const VERSION: u32 = 1;

/// Writes snapshots of a field with `C` components to `writer` (see the [module](self)).
///
/// ```
/// use dirac_runtime::snapshots::{SnapshotWriter, Snapshots};
/// use nalgebra::SVector;
///
/// let positions = [0.0, 0.5, 1.0];
/// let mut writer = SnapshotWriter::<_, 1>::new(Vec::new(), &positions)?;
/// for t in [0.0, 0.1] {
///     let u: Vec<SVector<f64, 1>> = positions.iter().map(|x| SVector::from([x + t])).collect();
///     writer.write(t, &u)?;
/// }
/// let bytes = writer.finish()?;
/// assert_eq!(bytes.len(), 24 + 3 * 8 + 2 * (1 + 3) * 8);
/// let read = Snapshots::<1>::read(&bytes[..])?;
/// assert_eq!((read.positions.as_slice(), read.t.as_slice()), (&positions[..], &[0.0, 0.1][..]));
/// assert_eq!(read.u[1][2][0], 1.1);
/// # Ok::<(), dirac_runtime::DiracError>(())
/// ```
#[derive(Debug)]
pub struct SnapshotWriter<W: Write, const C: usize> {
    writer: W,
    nodes: usize,
    /// One snapshot's bytes, reused.
    buffer: Vec<u8>,
}

impl<W: Write, const C: usize> SnapshotWriter<W, C> {
    /// Writes the header: the nodes' `positions` (finite), which fix the number of nodes of
    /// every snapshot. `Io` where writing fails.
    pub fn new(mut writer: W, positions: &[f64]) -> Result<Self, DiracError> {
        if let Some(x) = positions.iter().find(|x| !x.is_finite()) {
            return Err(DiracError::NonFinite {
                what: "a node's position".into(),
                value: *x,
            });
        }
        let components = u32::try_from(C)
            .map_err(|_| DiracError::Dimension(format!("{C} components do not fit the header")))?;
        let mut header = Vec::with_capacity(24 + 8 * positions.len());
        header.extend_from_slice(MAGIC);
        header.extend_from_slice(&VERSION.to_le_bytes());
        header.extend_from_slice(&components.to_le_bytes());
        header.extend_from_slice(&(positions.len() as u64).to_le_bytes());
        for x in positions {
            header.extend_from_slice(&x.to_le_bytes());
        }
        writer.write_all(&header).map_err(io)?;
        Ok(Self {
            writer,
            nodes: positions.len(),
            buffer: Vec::with_capacity(8 * (1 + C * positions.len())),
        })
    }

    /// Appends the snapshot `(t, u)`; `Dimension` (nothing written) where `u` has another number
    /// of nodes than the header.
    pub fn write(&mut self, t: f64, u: &[SVector<f64, C>]) -> Result<(), DiracError> {
        if u.len() != self.nodes {
            return Err(DiracError::Dimension(format!(
                "a snapshot of {} nodes in a file of {}",
                u.len(),
                self.nodes
            )));
        }
        self.buffer.clear();
        self.buffer.extend_from_slice(&t.to_le_bytes());
        for value in u.iter().flat_map(|node| node.iter()) {
            self.buffer.extend_from_slice(&value.to_le_bytes());
        }
        self.writer.write_all(&self.buffer).map_err(io)
    }

    /// Appends the field's current time and values (`NotStarted` before its start).
    pub fn record<D: SeparableDensity<C>>(
        &mut self,
        field: &Field<D, C>,
    ) -> Result<(), DiracError> {
        self.write(field.t(), field.u()?)
    }

    /// Flushes and returns the writer.
    pub fn finish(mut self) -> Result<W, DiracError> {
        self.writer.flush().map_err(io)?;
        Ok(self.writer)
    }
}

/// Snapshots read back from a file [`SnapshotWriter`] wrote.
#[derive(Debug, Clone, PartialEq)]
pub struct Snapshots<const C: usize> {
    /// The nodes' positions.
    pub positions: Vec<f64>,
    /// Each snapshot's time.
    pub t: Vec<f64>,
    /// Each snapshot's values, node by node.
    pub u: Vec<Vec<SVector<f64, C>>>,
}

impl<const C: usize> Snapshots<C> {
    /// Reads every snapshot of `reader`. `Io` for another file (its magic or version), another
    /// number of components than `C`, or a file that ends inside its header or a snapshot.
    pub fn read<R: Read>(mut reader: R) -> Result<Self, DiracError> {
        let mut bytes = Vec::new();
        reader.read_to_end(&mut bytes).map_err(io)?;
        let invalid = |why: String| Err(DiracError::Io(format!("not a snapshot file: {why}")));
        if bytes.len() < 24 || &bytes[..8] != MAGIC {
            return invalid("it does not begin with DIRACSNP".into());
        }
        let word = |at: usize| u32::from_le_bytes(bytes[at..at + 4].try_into().expect("4 bytes"));
        let version = word(8);
        if version != VERSION {
            return invalid(format!("version {version}, this reader reads {VERSION}"));
        }
        let components = word(12) as usize;
        if components != C {
            return Err(DiracError::Dimension(format!(
                "the file holds {components} components a node, read as {C}"
            )));
        }
        let nodes = u64::from_le_bytes(bytes[16..24].try_into().expect("8 bytes"));
        let floats = |from: usize| {
            bytes[from..]
                .chunks_exact(8)
                .map(|b| f64::from_le_bytes(b.try_into().expect("8 bytes")))
        };
        let header = usize::try_from(nodes)
            .ok()
            .and_then(|n| n.checked_mul(8))
            .and_then(|b| b.checked_add(24))
            .filter(|&end| end <= bytes.len());
        let Some(header) = header else {
            return invalid(format!("it ends inside the positions of its {nodes} nodes"));
        };
        let nodes = nodes as usize;
        let positions: Vec<f64> = floats(24).take(nodes).collect();
        let snapshot = 8 * (1 + C * nodes);
        let rest = bytes.len() - header;
        if rest % snapshot != 0 {
            return invalid(format!(
                "it ends inside a snapshot ({} bytes past the last whole one)",
                rest % snapshot
            ));
        }
        let count = rest / snapshot;
        let (mut t, mut u) = (Vec::with_capacity(count), Vec::with_capacity(count));
        for k in 0..count {
            let mut values = floats(header + k * snapshot).take(1 + C * nodes);
            t.push(values.next().expect("a snapshot's time"));
            let all: Vec<f64> = values.collect();
            u.push(
                all.chunks_exact(C.max(1))
                    .map(SVector::<f64, C>::from_column_slice)
                    .collect(),
            );
        }
        Ok(Self { positions, t, u })
    }
}

fn io(error: std::io::Error) -> DiracError {
    DiracError::Io(error.to_string())
}
