#pragma once
// Turns a case's `solid` section with element_family: HEXAHEDRON and its mesh file into a ready
// HexahedronSolver, the brick counterpart of case_setup.hpp (docs/solid_fe-hexahedron.md).
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "case.pb.h"
#include "valvefsi/solid/case_setup.hpp"  // MonitorSet, material_from_case
#include "valvefsi/solid/hexahedron_solver.hpp"
#include "valvefsi/solid/mesh.hpp"

namespace valvefsi::solid {

struct HexahedronSetup {
  std::filesystem::path mesh_file;
  Mesh mesh;
  std::unique_ptr<HexahedronSolver> solver;
  std::vector<PressureFace> pressure_faces;  // loaded by the FE-only pressure
  std::vector<MonitorSet> monitors;
  std::vector<std::string> notes;            // what was chosen, for the log
};

// The 3D material of the case: the shell law's parameters, with Ogden and neo-Hookean given the
// bulk modulus 2/D of the case's MHGO block (default D = 1e-5 /kPa -> 200 MPa).
SolidMaterial solid_material_from_case(const cases::SolidCase& solid, const std::string& source);

// Reads the mesh (it must have /mesh/hexahedra), checks the sets the case names and builds the
// solver: fixed node sets, symmetry planes (nodes within 1e-6 of the model size keep zero normal
// displacement), contact planes (node penalty), pressure faces = the ventricular outer faces of
// the hexahedron element sets in solid.pressure_element_sets (all bricks when empty).
// Throws CaseError for bad case values, std::invalid_argument / std::runtime_error for a bad mesh.
HexahedronSetup hexahedron_setup_from_case(const cases::Case& c, const std::filesystem::path& case_file);

}  // namespace valvefsi::solid
