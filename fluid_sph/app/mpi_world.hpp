#pragma once
// fluid_sph's view of MPI: initialised only when a launcher started it (mpirun sets these
// variables), so a plain start stays one process without an MPI runtime. Rank 0 logs, writes
// the outputs and (coupled) owns the Participant; the others compute their slabs.
#include <mpi.h>

#include <cstdlib>
#include <string>

#include "valvefsi/fluid/fluid_solver.hpp"

namespace valvefsi::fluid::app {

inline bool started_by_mpi_launcher() {
  for (const char* variable : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK", "MPI_LOCALNRANKS"})
    if (std::getenv(variable) != nullptr) return true;
  return false;
}

struct MpiWorld {
  int rank = 0;
  int size = 1;
  bool root() const { return rank == 0; }
  bool split() const { return size > 1; }
};

inline MpiWorld mpi_world() {
  int initialised = 0;
  MPI_Initialized(&initialised);
  MpiWorld world;
  if (initialised == 0) return world;
  MPI_Comm_rank(MPI_COMM_WORLD, &world.rank);
  MPI_Comm_size(MPI_COMM_WORLD, &world.size);
  return world;
}

// Rank 0's value on every rank (no-op on one rank).
inline void broadcast(const MpiWorld& world, std::string& text) {
  if (!world.split()) return;
  unsigned long long length = text.size();
  MPI_Bcast(&length, 1, MPI_UNSIGNED_LONG_LONG, 0, MPI_COMM_WORLD);
  text.resize(length);
  MPI_Bcast(text.data(), static_cast<int>(length), MPI_CHAR, 0, MPI_COMM_WORLD);
}
inline void broadcast(const MpiWorld& world, double* values, int count) {
  if (world.split()) MPI_Bcast(values, count, MPI_DOUBLE, 0, MPI_COMM_WORLD);
}

// Particles of a kind over all ranks (each rank counts its own).
template <int D>
std::size_t count_over_ranks(const FluidSolver<D>& solver, Kind kind) {
  const auto& p = solver.particles();
  const auto [first, last] = solver.owned_range();
  double n = 0;
  for (std::size_t i = first; i < last; ++i) n += p.kind[i] == kind;
  if (solver.decomposition() != nullptr) n = solver.decomposition()->sum(n);
  return static_cast<std::size_t>(n);
}

// Particle updates per step over all ranks (own particles, images included, halo not).
template <int D>
double particles_over_ranks(const FluidSolver<D>& solver) {
  const auto [first, last] = solver.owned_range();
  const double n = static_cast<double>(last - first);
  return solver.decomposition() != nullptr ? solver.decomposition()->sum(n) : n;
}

}  // namespace valvefsi::fluid::app
