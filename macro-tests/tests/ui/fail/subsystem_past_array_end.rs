use dirac::prelude::*;

#[dirac_system(coordinates(q), lagrangian = 0.5 * dot(q).powi(2))]
#[derive(Clone, Copy)]
struct Cell;

#[dirac_system(subsystems(cells), junctions(for i in 0..3 { glue = cells[i].dq - cells[i + 1].dq }))]
struct Chain {
    cells: [Cell; 3],
}

fn main() {}
