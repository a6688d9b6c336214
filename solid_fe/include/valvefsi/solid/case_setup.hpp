#pragma once
// Turns a case's `solid` section and its mesh file into a ready solver (docs/solid_fe.md).
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "case.pb.h"
#include "valvefsi/solid/mesh.hpp"
#include "valvefsi/solid/shell_solver.hpp"

namespace valvefsi::solid {

struct MonitorSet {
  std::string name;
  std::vector<std::int64_t> nodes;
};

struct SolidSetup {
  std::filesystem::path mesh_file;
  Mesh mesh;
  std::unique_ptr<ShellSolver> solver;
  std::vector<std::int64_t> pressure_elements;  // empty: all triangles
  std::vector<MonitorSet> monitors;
  std::vector<std::string> notes;                // what was chosen, for the log
  int dimension = 3;                             // run.dimension
  double strip_depth = 0;                        // 2D: solid.strip_depth (m)
  std::vector<StripTie> strip_ties;              // 2D: strip_front[k] with strip_back[k]
};

// Material from the case (parameters converted to SI). Throws CaseError naming the field.
Material material_from_case(const cases::SolidCase& solid, const std::string& source);

// Reads the mesh, checks the sets the case names and builds the solver. Throws CaseError
// (bad case values) or std::runtime_error / std::invalid_argument (bad mesh file).
SolidSetup setup_from_case(const cases::Case& c, const std::filesystem::path& case_file);

}  // namespace valvefsi::solid
