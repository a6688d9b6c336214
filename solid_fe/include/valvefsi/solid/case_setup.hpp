#pragma once
// Turns a case's `solid` section and its mesh file into a ready solver (docs/solid_fe.md): one
// path for both element families (solid.element_family SHELL or HEXAHEDRON).
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "case.pb.h"
#include "valvefsi/solid/explicit_solver.hpp"
#include "valvefsi/solid/hexahedron_elements.hpp"
#include "valvefsi/solid/hexahedron_material.hpp"
#include "valvefsi/solid/material.hpp"
#include "valvefsi/solid/mesh.hpp"

namespace valvefsi::solid {

class ShellSolver;
class HexahedronSolver;

struct MonitorSet {
  std::string name;
  std::vector<std::int64_t> nodes;
};

struct SolidSetup {
  std::filesystem::path mesh_file;
  Mesh mesh;
  ElementFamily element_family = ElementFamily::shell;
  std::unique_ptr<ExplicitSolver> solver;       // a ShellSolver or a HexahedronSolver
  std::vector<std::int64_t> pressure_elements;  // shells: loaded triangles (empty: all)
  std::vector<PressureFace> pressure_faces;     // bricks: loaded ventricular faces
  std::vector<MonitorSet> monitors;
  std::vector<std::string> notes;                // what was chosen, for the log
  int dimension = 3;                             // run.dimension
  double strip_depth = 0;                        // 2D: solid.strip_depth (m)
  std::vector<StripTie> strip_ties;              // 2D: strip_front[k] with strip_back[k]

  // The solver as its family (std::logic_error if it is the other one).
  ShellSolver& shell_solver() const;
  HexahedronSolver& hexahedron_solver() const;
};

// Material from the case (parameters converted to SI). Throws CaseError naming the field.
Material material_from_case(const cases::SolidCase& solid, const std::string& source);

// The 3D material of the case for bricks: the shell law's parameters, with Ogden and neo-Hookean
// given the bulk modulus 2/D of the case's MHGO block (default D = 1e-5 /kPa -> 200 MPa).
SolidMaterial solid_material_from_case(const cases::SolidCase& solid, const std::string& source);

// Reads the mesh, checks the sets the case names and builds the solver: fixed node sets,
// symmetry planes (nodes within 1e-6 of the model size keep zero normal displacement), contact
// planes and cylinders, leaflet contact (shells), 2D strip ties (shells), the pressure surface
// (shells: the triangles of solid.pressure_element_sets; bricks: the ventricular outer faces of
// those hexahedron sets; all when empty). The pressure waveform is the caller's
// (ExplicitSolver::set_pressure_waveform). Throws CaseError (bad case values) or
// std::runtime_error / std::invalid_argument (bad mesh file).
SolidSetup setup_from_case(const cases::Case& c, const std::filesystem::path& case_file);

// Coupled (participant) runs: refuses (CaseError naming the case file, the field, its value and
// what is allowed) the FE-only fields, solid.diastolic_mass_damping_per_s > 0.
void check_coupled_solid_case(const cases::Case& c, const std::filesystem::path& case_file);

}  // namespace valvefsi::solid
