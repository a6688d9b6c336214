#pragma once
// Restart files of the solid (docs/solid_fe.md, "Restarts"): the explicit solver's whole state
// (SolverState: positions, both velocities, the forces of the last evaluation, step history with
// the uncut step and the calibration, energy ledger, contact stiffness and candidate pairs, tip
// ties) as named arrays in a valvefsi_restart file, so a run continued from it repeats the
// uninterrupted run bit for bit (same case, same thread count).
#include <filesystem>

#include "valvefsi/solid/explicit_solver.hpp"

namespace valvefsi::coupling {
class RestartWriter;
class RestartReader;
}  // namespace valvefsi::coupling

namespace valvefsi::solid {

// Adds the solver's state to an open restart file (the caller commits it).
void write_solver_restart(const ExplicitSolver& solver, coupling::RestartWriter& file);
// Writes <file> whole (temporary name, renamed when complete).
void write_solver_restart(const ExplicitSolver& solver, const std::filesystem::path& file);

// Replaces the solver's state by the file's. Throws std::runtime_error naming the file and the
// entry when one is missing, or when the file was written for another mesh (node count) or
// another element family.
void read_solver_restart(const coupling::RestartReader& file, ExplicitSolver& solver);
void read_solver_restart(const std::filesystem::path& file, ExplicitSolver& solver);

}  // namespace valvefsi::solid
