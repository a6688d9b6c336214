#pragma once
// Turns the `fluid` section of a case file (proto/fluid_case.proto) into solver settings,
// scene geometry, pressure plates and probes. Errors name the file, the field, the value and
// what is allowed (valvefsi::CaseError).
#include <filesystem>
#include <string>
#include <vector>

#include "case.pb.h"
#include "valvefsi/fluid/fluid_solver.hpp"
#include "valvefsi/fluid/geometry.hpp"
#include "valvefsi/fluid/probes.hpp"

namespace valvefsi::fluid {

template <int D>
struct NamedPoint {
  std::string name;
  Vec<D> position{};
};

template <int D>
struct NamedPlane {
  std::string name;
  ProbePlane<D> plane;
};

template <int D>
struct ProbeSet {
  std::vector<NamedPoint<D>> pressure_points;
  std::vector<NamedPlane<D>> flow_planes;
  std::vector<NamedPlane<D>> velocity_planes;
  bool wall_forces = false;
};

template <int D>
struct FluidSetup {
  FluidSettings<D> settings;
  SceneGeometry<D> scene;
  int wall_layers = 0;
  std::vector<PressurePlate<D>> plates;  // mass 0 means: set from the plate's particles
  ProbeSet<D> probes;
};

template <int D>
FluidSetup<D> fluid_setup_from_case(const cases::Case& c, const std::filesystem::path& case_file);

// Fills the particles and builds the solver (plate masses from their particles if unset).
template <int D>
FluidSolver<D> make_solver(FluidSetup<D> setup);

}  // namespace valvefsi::fluid
