use dirac::prelude::*;

#[dirac_system(coordinates(q), lagrangian = 0.5 * dot(q).powi(2))]
#[derive(Clone, Copy)]
struct Cell;

const CELLS: usize = 3;

#[dirac_system(subsystems(cells))]
struct Chain {
    cells: [Cell; CELLS],
}

fn main() {}
