#include "valvefsi/solid/hexahedron_setup.hpp"

#include <cmath>
#include <set>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "valvefsi/case/case_loader.hpp"

namespace valvefsi::solid {
namespace {

const std::vector<std::int64_t>& named_node_set(const Mesh& mesh, const std::string& name, const std::string& field,
                                                const std::string& source, const std::string& mesh_file) {
  const auto it = mesh.node_sets.find(name);
  if (it == mesh.node_sets.end()) {
    std::string names;
    for (const auto& [n, _] : mesh.node_sets) names += (names.empty() ? "" : ", ") + n;
    throw CaseError(fmt::format("{}: field '{}' = \"{}\": no such node set in {} (it has: {})", source, field, name,
                                mesh_file, names.empty() ? "none" : names));
  }
  return it->second;
}

}  // namespace

SolidMaterial solid_material_from_case(const cases::SolidCase& solid, const std::string& source) {
  cases::SolidCase filled = solid;
  filled.mutable_mhgo();
  apply_field_limits(filled, source, "solid");
  const double bulk_modulus = 2.0 / (filled.mhgo().d_per_kpa() * 1e-3);
  return solid_material_from(material_from_case(solid, source), bulk_modulus);
}

HexahedronSetup hexahedron_setup_from_case(const cases::Case& c, const std::filesystem::path& case_file) {
  const std::string source = case_file.string();
  if (!c.has_solid()) {
    throw CaseError(fmt::format("{}: the case has no 'solid' section; solid_fe needs one", source));
  }
  cases::SolidCase solid = c.solid();
  apply_field_limits(solid, source, "solid");
  HexahedronSetup setup;
  setup.mesh_file = resolve_case_path(case_file, solid.mesh_file());
  setup.mesh = read_mesh(setup.mesh_file);
  const Mesh& mesh = setup.mesh;
  const std::string mesh_name = setup.mesh_file.string();
  if (mesh.hexahedra.empty()) {
    throw CaseError(fmt::format("{}: solid.element_family = HEXAHEDRON but {} has no /mesh/hexahedra "
                                "(write it with scripts/valve_scene/generate.py --elements both|hexahedra)",
                                source, mesh_name));
  }

  HexahedronModelOptions options;
  options.density = solid.density();
  std::vector<std::string> fixed_sets(solid.fixed_node_sets().begin(), solid.fixed_node_sets().end());
  if (fixed_sets.empty()) fixed_sets.push_back("attachment");
  std::set<std::int64_t> fixed;
  for (const auto& name : fixed_sets) {
    const auto& nodes = named_node_set(mesh, name, "solid.fixed_node_sets", source, mesh_name);
    fixed.insert(nodes.begin(), nodes.end());
  }
  options.fixed_nodes.assign(fixed.begin(), fixed.end());

  std::vector<std::int64_t> loaded;
  for (const auto& name : solid.pressure_element_sets()) {
    const auto it = mesh.element_sets.find(name);
    if (it == mesh.element_sets.end() || mesh.element_set_types.at(name) != "hexahedron") {
      throw CaseError(fmt::format("{}: field 'solid.pressure_element_sets' = \"{}\": no hexahedron element set of "
                                  "that name in {} (element_family is HEXAHEDRON)", source, name, mesh_name));
    }
    loaded.insert(loaded.end(), it->second.begin(), it->second.end());
  }
  setup.pressure_faces = ventricular_faces(mesh, loaded);

  std::vector<std::string> monitor_sets(solid.monitor_node_sets().begin(), solid.monitor_node_sets().end());
  if (monitor_sets.empty() && mesh.node_sets.count("free_edge_midpoints") != 0) {
    monitor_sets.push_back("free_edge_midpoints");
  }
  for (const auto& name : monitor_sets) {
    setup.monitors.push_back({name, named_node_set(mesh, name, "solid.monitor_node_sets", source, mesh_name)});
  }

  HexahedronSolverOptions solver_options;
  solver_options.time_step_safety = solid.time_step_safety();
  solver_options.time_step_update_interval = solid.time_step_update_interval();
  solver_options.mass_damping_per_s = solid.mass_damping_per_s();
  solver_options.max_time_step = solid.max_time_step();
  solver_options.contact_stiffness_factor = solid.contact_stiffness_factor();

  SolidMaterial material = solid_material_from_case(solid, source);
  setup.notes.push_back(fmt::format(
      "mesh {}: {} nodes, {} hexahedra; material {} (3D, bulk modulus {:.4g} MPa); {} fixed nodes ({}); "
      "{} pressure faces", mesh_name, mesh.num_nodes(), mesh.hexahedra.size(),
      material_name(material_from_case(solid, source)), bulk_modulus(material) * 1e-6, options.fixed_nodes.size(),
      fmt::join(fixed_sets, ", "), setup.pressure_faces.size()));
  if (solver_options.mass_damping_per_s > 0.0) {
    setup.notes.push_back(fmt::format("mass-proportional damping ON: alpha = {} 1/s", solver_options.mass_damping_per_s));
  }
  setup.solver = std::make_unique<HexahedronSolver>(build_hexahedron_model(mesh, options, mesh_name),
                                                    std::move(material), solver_options);

  const double size = (mesh.nodes.rowwise().maxCoeff() - mesh.nodes.rowwise().minCoeff()).norm();
  for (const auto& [name, plane] : mesh.symmetry_planes) {
    std::vector<SymmetryConstraint> on_plane;
    for (Eigen::Index n = 0; n < mesh.nodes.cols(); ++n) {
      if (std::abs((mesh.nodes.col(n) - plane.point).dot(plane.normal)) <= 1e-6 * size) {
        on_plane.push_back({n, plane.normal});
      }
    }
    setup.notes.push_back(fmt::format("symmetry plane '{}': {} nodes", name, on_plane.size()));
    setup.solver->add_symmetry_constraints(on_plane);
  }
  for (const auto& [name, plane] : mesh.contact_planes) {
    setup.notes.push_back(fmt::format("contact plane '{}': node penalty (no leaflet-leaflet contact for bricks)", name));
    setup.solver->add_contact_plane(plane);
  }
  return setup;
}

}  // namespace valvefsi::solid
