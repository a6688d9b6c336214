#include "valvefsi/solid/case_setup.hpp"

#include <algorithm>
#include <cmath>
#include <set>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "valvefsi/case/case_loader.hpp"
#include "valvefsi/case/pressure_waveform.hpp"
#include "valvefsi/solid/hexahedron_solver.hpp"
#include "valvefsi/solid/shell_solver.hpp"

namespace valvefsi::solid {

Material material_from_case(const cases::SolidCase& solid_in, const std::string& source) {
  // Fill the parameter blocks' documented defaults even when the case leaves them out.
  cases::SolidCase solid = solid_in;
  solid.mutable_mhgo();
  solid.mutable_ogden();
  solid.mutable_neo_hookean();
  solid.mutable_saint_venant_kirchhoff();
  apply_field_limits(solid, source, "solid");
  switch (solid.material()) {
    case cases::SolidCase::MHGO: {
      const auto& m = solid.mhgo();
      MhgoParameters p;
      p.c10_Pa = m.c10_kpa() * 1e3;
      p.c01 = m.c01();
      p.k1_Pa = m.k1_kpa() * 1e3;
      p.k2 = m.k2();
      p.fibre_angle_rad = m.fibre_angle_deg() * M_PI / 180.0;
      p.d_per_Pa = m.d_per_kpa() * 1e-3;
      return Mhgo(p);
    }
    case cases::SolidCase::OGDEN: {
      const auto& m = solid.ogden();
      if (m.alpha1() == 0.0 || m.alpha2() == 0.0) {
        throw CaseError(fmt::format("{}: field 'solid.ogden.alpha1/alpha2' = 0: allowed non-zero", source));
      }
      OgdenParameters p;
      p.mu_Pa = {m.mu1_kpa() * 1e3, m.mu2_kpa() * 1e3};
      p.alpha = {m.alpha1(), m.alpha2()};
      return Ogden(p);
    }
    case cases::SolidCase::NEO_HOOKEAN:
      return NeoHookean(solid.neo_hookean().shear_modulus_kpa() * 1e3);
    case cases::SolidCase::SAINT_VENANT_KIRCHHOFF:
      return SaintVenantKirchhoff(solid.saint_venant_kirchhoff().youngs_modulus_kpa() * 1e3,
                                  solid.saint_venant_kirchhoff().poisson_ratio());
    default:
      throw CaseError(fmt::format("{}: field 'solid.material' = {}: unknown material", source,
                                  static_cast<int>(solid.material())));
  }
}

SolidMaterial solid_material_from_case(const cases::SolidCase& solid, const std::string& source) {
  cases::SolidCase filled = solid;
  filled.mutable_mhgo();
  apply_field_limits(filled, source, "solid");
  const double bulk_modulus = 2.0 / (filled.mhgo().d_per_kpa() * 1e-3);
  return solid_material_from(material_from_case(solid, source), bulk_modulus);
}

ShellSolver& SolidSetup::shell_solver() const {
  auto* s = dynamic_cast<ShellSolver*>(solver.get());
  if (s == nullptr) throw std::logic_error("solid setup: the solver is not a shell solver");
  return *s;
}

HexahedronSolver& SolidSetup::hexahedron_solver() const {
  auto* s = dynamic_cast<HexahedronSolver*>(solver.get());
  if (s == nullptr) throw std::logic_error("solid setup: the solver is not a hexahedron solver");
  return *s;
}

namespace {

// solid.implicit_tangent_cost when unset: off. At the measured price (a tangent ~20 explicit
// steps) the rule made the coarse sector's cycle slower (its closed leaflet's implicit phases
// are expensive until they have damped the ringing, which the explicit phases do not) and the
// full valve's 200-270 ms no cheaper than explicit (docs/solid_fe.md, "Fourteenth session").
constexpr double kDefaultImplicitTangentCost = 0.0;

const std::vector<std::int64_t>& node_set(const Mesh& mesh, const std::string& name, const std::string& field,
                                          const std::string& source, const std::string& mesh_file) {
  const auto it = mesh.node_sets.find(name);
  if (it == mesh.node_sets.end()) {
    std::string names;
    for (const auto& [n, _] : mesh.node_sets) names += (names.empty() ? "" : ", ") + n;
    throw CaseError(fmt::format("{}: field '{}' = \"{}\": no such node set in {} (it has: {})", source, field,
                                name, mesh_file, names.empty() ? "none" : names));
  }
  return it->second;
}

}  // namespace

void check_coupled_solid_case(const cases::Case& c, const std::filesystem::path& case_file) {
  if (c.solid().diastolic_mass_damping_per_s() > 0.0) {
    throw CaseError(fmt::format("{}: field 'solid.diastolic_mass_damping_per_s' = {} in a coupled run: it stands in "
                                "for the blood's damping of the closed valve under the FE-only pressure waveform; "
                                "allowed > 0 only in FE-only runs (solid_fe --fe-only or run.fe_only: true), 0 when "
                                "coupled (the fluid damps the valve)",
                                case_file.string(), c.solid().diastolic_mass_damping_per_s()));
  }
}

SolidSetup setup_from_case(const cases::Case& c, const std::filesystem::path& case_file) {
  const std::string source = case_file.string();
  if (!c.has_solid()) {
    throw CaseError(fmt::format("{}: the case has no 'solid' section; solid_fe needs one", source));
  }
  cases::SolidCase solid = c.solid();
  apply_field_limits(solid, source, "solid");
  SolidSetup setup;
  setup.mesh_file = resolve_case_path(case_file, solid.mesh_file());
  setup.mesh = read_mesh(setup.mesh_file);
  const Mesh& mesh = setup.mesh;
  const std::string mesh_name = setup.mesh_file.string();
  const bool bricks = solid.element_family() == cases::SolidCase::HEXAHEDRON;
  setup.element_family = bricks ? ElementFamily::hexahedron : ElementFamily::shell;
  const bool implicit = solid.time_integration() != cases::SolidCase::EXPLICIT;
  const std::string integration = cases::SolidCase::TimeIntegration_Name(solid.time_integration());
  if (bricks && implicit) {
    throw CaseError(fmt::format("{}: field 'solid.time_integration' = {} with solid.element_family = "
                                "HEXAHEDRON: allowed only for SHELL (no brick tangent yet)", source, integration));
  }
  if (solid.has_leaflet_contact_damping_ratio() && solid.leaflet_contact_damping_ratio() > 0.0 &&
      (bricks || solid.disable_leaflet_contact())) {
    throw CaseError(fmt::format("{}: field 'solid.leaflet_contact_damping_ratio' = {} with {}: it damps the "
                                "leaflet-leaflet contact pairs; allowed > 0 only for SHELL elements with leaflet "
                                "contact on (0 otherwise)",
                                source, solid.leaflet_contact_damping_ratio(),
                                bricks ? "solid.element_family = HEXAHEDRON" : "solid.disable_leaflet_contact = true"));
  }
  if (solid.leaflet_self_contact() && (bricks || solid.disable_leaflet_contact())) {
    throw CaseError(fmt::format("{}: field 'solid.leaflet_self_contact' = true with {}: allowed only for SHELL "
                                "elements with leaflet contact on", source,
                                bricks ? "solid.element_family = HEXAHEDRON" : "solid.disable_leaflet_contact = true"));
  }
  if (!bricks && mesh.triangles.empty()) {
    throw CaseError(fmt::format("{}: solid.element_family = SHELL but {} has no /mesh/triangles", source, mesh_name));
  }
  if (bricks && mesh.hexahedra.empty()) {
    throw CaseError(fmt::format("{}: solid.element_family = HEXAHEDRON but {} has no /mesh/hexahedra "
                                "(write it with scripts/valve_scene/generate.py --elements hexahedra)",
                                source, mesh_name));
  }
  setup.dimension = c.run().has_dimension() ? c.run().dimension() : 3;
  if (bricks && setup.dimension == 2) {
    throw CaseError(fmt::format("{}: field 'run.dimension' = 2 with solid.element_family = HEXAHEDRON: 2D strips "
                                "are shells; allowed: SHELL", source));
  }

  ShellModelOptions options;
  options.density = solid.density();
  options.thickness_points = solid.thickness_points();
  options.clamp_fixed_edges = !solid.hinged_fixed_edges();
  for (const auto& [name, plane] : mesh.symmetry_planes) options.symmetry_planes.push_back(plane);
  std::vector<std::string> fixed_sets(solid.fixed_node_sets().begin(), solid.fixed_node_sets().end());
  if (fixed_sets.empty()) fixed_sets.push_back("attachment");
  std::set<std::int64_t> fixed;
  for (const auto& name : fixed_sets) {
    const auto& nodes = node_set(mesh, name, "solid.fixed_node_sets", source, mesh_name);
    fixed.insert(nodes.begin(), nodes.end());
  }
  options.fixed_nodes.assign(fixed.begin(), fixed.end());

  const std::string element_type = bricks ? "hexahedron" : "triangle";
  std::vector<std::int64_t> loaded;
  for (const auto& name : solid.pressure_element_sets()) {
    const auto it = mesh.element_sets.find(name);
    if (it == mesh.element_sets.end() || mesh.element_set_types.at(name) != element_type) {
      throw CaseError(fmt::format("{}: field 'solid.pressure_element_sets' = \"{}\": no {} element set "
                                  "of that name in {} (solid.element_family is {})", source, name, element_type,
                                  mesh_name, bricks ? "HEXAHEDRON" : "SHELL"));
    }
    loaded.insert(loaded.end(), it->second.begin(), it->second.end());
  }

  std::vector<std::string> monitor_sets(solid.monitor_node_sets().begin(), solid.monitor_node_sets().end());
  if (monitor_sets.empty() && mesh.node_sets.count("free_edge_midpoints") != 0) {
    monitor_sets.push_back("free_edge_midpoints");
  }
  for (const auto& name : monitor_sets) {
    setup.monitors.push_back({name, node_set(mesh, name, "solid.monitor_node_sets", source, mesh_name)});
  }

  SolverOptions solver_options;
  solver_options.time_step_safety = solid.time_step_safety();
  solver_options.time_step_update_interval = solid.time_step_update_interval();
  solver_options.time_step_calibration_interval = solid.time_step_calibration_interval();
  solver_options.max_step_calibration = solid.max_time_step_calibration();
  solver_options.max_time_step_growth = solid.max_time_step_growth();
  solver_options.mass_damping_per_s = solid.mass_damping_per_s();
  solver_options.max_time_step = solid.max_time_step();
  solver_options.contact_stiffness_factor = solid.contact_stiffness_factor();
  solver_options.max_energy_balance_error = solid.max_energy_balance_error();
  solver_options.fixed_time_step = solid.forced_time_step();
  solver_options.time_step_look_ahead = solid.time_step_look_ahead();
  solver_options.contact_damping_ratio = solid.leaflet_contact_damping_ratio();
  solver_options.diastolic_mass_damping_per_s = solid.diastolic_mass_damping_per_s();
  solver_options.diastolic_damping_onset_Pa = solid.diastolic_damping_onset_mmhg() * kPascalPerMmHg;
  if (solid.diastolic_damping_onset_mmhg() > 0.0 && solid.diastolic_mass_damping_per_s() <= 0.0) {
    throw CaseError(fmt::format("{}: field 'solid.diastolic_damping_onset_mmHg' = {} without "
                                "solid.diastolic_mass_damping_per_s > 0: it sets where that damping starts; "
                                "set both or neither",
                                source, solid.diastolic_damping_onset_mmhg()));
  }
  if (solid.has_implicit_tangent_cost() && solid.time_integration() != cases::SolidCase::AUTOMATIC) {
    throw CaseError(fmt::format("{}: field 'solid.implicit_tangent_cost' = {} with solid.time_integration = {}: "
                                "it prices the automatic switch's implicit steps; allowed only with "
                                "time_integration AUTOMATIC (>= 0; 0 turns the cost rule off)",
                                source, solid.implicit_tangent_cost(), integration));
  }
  if (solid.settled_filter_time_s() > 0.0 && solid.time_integration() != cases::SolidCase::AUTOMATIC) {
    throw CaseError(fmt::format("{}: field 'solid.settled_filter_time_s' = {} with solid.time_integration = {}: "
                                "it filters the automatic switch's kinetic energy; allowed > 0 only with "
                                "time_integration AUTOMATIC (0 otherwise)",
                                source, solid.settled_filter_time_s(), integration));
  }
  if (implicit) {
    if (setup.dimension == 2) {
      throw CaseError(fmt::format("{}: field 'solid.time_integration' = {} with run.dimension = 2: allowed "
                                  "only in 3D (2D strip ties are not in the implicit path)", source, integration));
    }
    solver_options.time_integration = solid.time_integration() == cases::SolidCase::AUTOMATIC
                                          ? TimeIntegration::automatic
                                          : TimeIntegration::implicit_generalized_alpha;
    if (solid.moving_kinetic_ratio() < solid.settled_kinetic_ratio()) {
      throw CaseError(fmt::format("{}: field 'solid.moving_kinetic_ratio' = {}: allowed >= "
                                  "solid.settled_kinetic_ratio ({})", source, solid.moving_kinetic_ratio(),
                                  solid.settled_kinetic_ratio()));
    }
    solver_options.settled_kinetic_ratio = solid.settled_kinetic_ratio();
    solver_options.settled_hold = solid.settled_hold_s();
    solver_options.moving_kinetic_ratio = solid.moving_kinetic_ratio();
    solver_options.settled_filter_time = solid.settled_filter_time_s();
    if (solid.time_integration() == cases::SolidCase::AUTOMATIC) {
      solver_options.implicit_tangent_cost =
          solid.has_implicit_tangent_cost() ? solid.implicit_tangent_cost() : kDefaultImplicitTangentCost;
    }
    if (solver_options.settled_filter_time > 0.0) {
      setup.notes.push_back(fmt::format(
          "automatic switch on the kinetic energy low-pass filtered over {} s (solid.settled_filter_time_s){}",
          solver_options.settled_filter_time,
          solid.spectral_radius_infinity() > 0.5
              ? fmt::format("; with spectral_radius_infinity {} > 0.5 the implicit phases it starts in the "
                            "moving leaflet were measured slower than explicit (docs/solid_fe.md)",
                            solid.spectral_radius_infinity())
              : ""));
    }
    solver_options.spectral_radius_infinity = solid.spectral_radius_infinity();
    solver_options.implicit_initial_step = solid.implicit_initial_step_s();
    solver_options.implicit_min_step = solid.implicit_min_step_s();
    solver_options.newton_tolerance = solid.newton_tolerance();
    solver_options.newton_max_iterations = solid.newton_max_iterations();
    setup.notes.push_back(fmt::format("implicit dynamics: generalized-alpha, rho_inf = {}, Newton tolerance {}",
                                      solver_options.spectral_radius_infinity, solver_options.newton_tolerance));
  }
  if (solver_options.fixed_time_step > 0.0) {
    setup.notes.push_back(fmt::format("forced time step {} s (solid.forced_time_step): no stable-step estimate",
                                      solver_options.fixed_time_step));
  }

  if (solver_options.mass_damping_per_s > 0.0) {
    setup.notes.push_back(fmt::format("mass-proportional damping ON: alpha = {} 1/s", solver_options.mass_damping_per_s));
  }
  if (solver_options.diastolic_mass_damping_per_s > 0.0) {
    setup.notes.push_back(fmt::format("diastolic mass-proportional damping ON: alpha = {} 1/s while the transvalvular "
                                      "pressure is below -{} mmHg (valve loaded closed), {} 1/s otherwise "
                                      "(solid.diastolic_mass_damping_per_s, solid.diastolic_damping_onset_mmHg)",
                                      solver_options.diastolic_mass_damping_per_s,
                                      solver_options.diastolic_damping_onset_Pa / kPascalPerMmHg,
                                      solver_options.mass_damping_per_s));
  }
  if (bricks) {
    HexahedronModelOptions brick_options;
    brick_options.density = options.density;
    brick_options.fixed_nodes = options.fixed_nodes;
    SolidMaterial material = solid_material_from_case(solid, source);
    setup.pressure_faces = ventricular_faces(mesh, loaded);
    setup.notes.push_back(fmt::format(
        "mesh {}: {} nodes, {} hexahedra; material {} (3D, bulk modulus {:.4g} MPa); {} fixed nodes ({}); "
        "{} pressure faces", mesh_name, mesh.num_nodes(), mesh.hexahedra.size(),
        material_name(material_from_case(solid, source)), bulk_modulus(material) * 1e-6, options.fixed_nodes.size(),
        fmt::join(fixed_sets, ", "), setup.pressure_faces.size()));
    auto solver = std::make_unique<HexahedronSolver>(build_hexahedron_model(mesh, brick_options, mesh_name),
                                                     std::move(material), solver_options);
    solver->set_pressure({}, setup.pressure_faces);
    setup.solver = std::move(solver);
  } else {
    setup.pressure_elements = loaded;
    Material material = material_from_case(solid, source);
    setup.notes.push_back(fmt::format("mesh {}: {} nodes, {} triangles; material {}; {} fixed nodes ({}), {} edges",
                                      mesh_name, mesh.num_nodes(), mesh.num_triangles(), material_name(material),
                                      options.fixed_nodes.size(), fmt::join(fixed_sets, ", "),
                                      options.clamp_fixed_edges ? "clamped" : "hinged"));
    auto solver = std::make_unique<ShellSolver>(build_shell_model(mesh, options, mesh_name), std::move(material),
                                                solver_options);
    solver->set_pressure({}, setup.pressure_elements);
    setup.solver = std::move(solver);
  }

  // Nodes on a mirror plane keep zero normal displacement.
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
    setup.notes.push_back(fmt::format("contact plane '{}': penalty contact of {}", name,
                                      bricks ? "the brick nodes" : "the mid-surface offset by t/2"));
    setup.solver->add_contact_plane(plane);
  }
  for (int k = 0; k < solid.contact_cylinders_size(); ++k) {
    const auto& cyl = solid.contact_cylinders(k);
    const std::string field = fmt::format("solid.contact_cylinders[{}]", k);
    if (cyl.origin_size() != 3 || cyl.axis_size() != 3) {
      throw CaseError(fmt::format("{}: field '{}': origin has {} and axis {} values; allowed 3 each", source, field,
                                  cyl.origin_size(), cyl.axis_size()));
    }
    ContactCylinder cylinder;
    cylinder.origin = Eigen::Vector3d(cyl.origin(0), cyl.origin(1), cyl.origin(2));
    cylinder.axis = Eigen::Vector3d(cyl.axis(0), cyl.axis(1), cyl.axis(2));
    cylinder.radius = cyl.radius();
    if (!(cylinder.axis.norm() > 0.0)) {
      throw CaseError(fmt::format("{}: field '{}.axis' = [0, 0, 0]: allowed a non-zero direction", source, field));
    }
    setup.notes.push_back(fmt::format("contact cylinder {}: radius {} m, axis [{}]: leaflets stay inside by t/2",
                                      k, cylinder.radius, fmt::join(cyl.axis(), ", ")));
    setup.solver->add_contact_cylinder(cylinder);
  }
  setup.strip_depth = solid.strip_depth();
  if (setup.dimension == 2) {
    const auto& front = node_set(mesh, "strip_front", "run.dimension = 2 needs node set", source, mesh_name);
    const auto& back = node_set(mesh, "strip_back", "run.dimension = 2 needs node set", source, mesh_name);
    if (front.size() != back.size() || front.empty()) {
      throw CaseError(fmt::format("{}: run.dimension = 2: {} has {} strip_front and {} strip_back nodes; allowed the "
                                  "same non-zero number (pairs in the same order)", source, mesh_name, front.size(),
                                  back.size()));
    }
    const double tolerance = 1e-6 * std::max(size, setup.strip_depth);
    for (std::size_t k = 0; k < front.size(); ++k) {
      const Eigen::Vector3d f = mesh.nodes.col(front[k]), b = mesh.nodes.col(back[k]);
      if (std::abs(f.z()) > tolerance || std::abs(b.z() - setup.strip_depth) > tolerance ||
          (f - b).head<2>().norm() > tolerance) {
        throw CaseError(fmt::format(
            "{}: run.dimension = 2: strip pair {} (nodes {}, {}) of {} is at [{}, {}, {}] and [{}, {}, {}]; allowed: "
            "front at z = 0, back at z = solid.strip_depth = {} m, same x and y", source, k, front[k], back[k],
            mesh_name, f.x(), f.y(), f.z(), b.x(), b.y(), b.z(), setup.strip_depth));
      }
      setup.strip_ties.push_back({front[k], back[k]});
    }
    setup.notes.push_back(fmt::format("2D plane-strain strip: {} front/back pairs tied, u_z = 0, depth {} m",
                                      front.size(), setup.strip_depth));
    setup.solver->set_strip_ties(setup.strip_ties);
  }
  if (solid.has_coaptation_tie()) {
    const auto& tie_case = solid.coaptation_tie();
    if (setup.dimension != 2 || bricks) {
      throw CaseError(fmt::format("{}: field 'solid.coaptation_tie': allowed for 2D shell strips only "
                                  "(run.dimension is {}, solid.element_family {})", source, setup.dimension,
                                  bricks ? "HEXAHEDRON" : "SHELL"));
    }
    const auto plane = mesh.contact_planes.find(tie_case.contact_plane());
    if (plane == mesh.contact_planes.end()) {
      std::vector<std::string> names;
      for (const auto& [name, p] : mesh.contact_planes) names.push_back(name);
      throw CaseError(fmt::format("{}: field 'solid.coaptation_tie.contact_plane' = \"{}\": {} has no such contact "
                                  "plane; allowed: [{}]", source, tie_case.contact_plane(), mesh_name,
                                  fmt::join(names, ", ")));
    }
    const std::string set_name = tie_case.node_set().empty() ? "free_edge" : tie_case.node_set();
    const auto& nodes = node_set(mesh, set_name, "solid.coaptation_tie.node_set", source, mesh_name);
    CoaptationTie tie;
    tie.plane = plane->second;
    tie.release_force = tie_case.release_force_n_per_m() * setup.strip_depth;
    std::set<std::int64_t> grouped;
    for (const std::int64_t n : nodes) {
      if (grouped.count(n) != 0) continue;
      std::vector<std::int64_t> group{n};
      for (const auto& t : setup.strip_ties) {
        if (t.front == n) group.push_back(t.back);
        if (t.back == n) group.push_back(t.front);
      }
      grouped.insert(group.begin(), group.end());
      tie.groups.push_back(std::move(group));
    }
    setup.notes.push_back(fmt::format("coaptation tie: {} tips of node set '{}' on contact plane '{}', release at "
                                      "{} N/m ({} N per tip)", tie.groups.size(), set_name, plane->first,
                                      tie_case.release_force_n_per_m(), tie.release_force));
    setup.solver->set_coaptation_tie(std::move(tie));
  }
  // Leaflet-leaflet contact between the surfaces named leaflet_0, leaflet_1, ...
  std::vector<int> surface_of_node(static_cast<std::size_t>(mesh.num_nodes()), -1);
  int leaflets = 0;
  for (; mesh.node_sets.count(fmt::format("leaflet_{}", leaflets)) != 0; ++leaflets) {
    for (const std::int64_t n : mesh.node_sets.at(fmt::format("leaflet_{}", leaflets))) {
      surface_of_node[static_cast<std::size_t>(n)] = leaflets;
    }
  }
  if (bricks) {
    setup.notes.push_back(fmt::format("leaflet-leaflet contact: not available for bricks ({} leaflet node set(s))",
                                      leaflets));
  } else if (solid.disable_leaflet_contact()) {
    setup.notes.push_back("leaflet-leaflet contact OFF (solid.disable_leaflet_contact)");
  } else if (solid.leaflet_self_contact()) {
    if (leaflets == 0) std::fill(surface_of_node.begin(), surface_of_node.end(), 0);
    setup.notes.push_back(fmt::format("leaflet contact between {} leaflet(s) (node sets leaflet_k{}) and within each "
                                      "(solid.leaflet_self_contact; neighbours within {:.3f} contact distances along "
                                      "the surface skipped)", std::max(leaflets, 1),
                                      leaflets == 0 ? "; none in the mesh: all nodes one leaflet" : "",
                                      kSelfContactExclusion));
    setup.solver->enable_leaflet_contact(std::move(surface_of_node), true);
  } else if (leaflets >= 2) {
    setup.notes.push_back(fmt::format("leaflet-leaflet contact between {} leaflets (node sets leaflet_k)", leaflets));
    setup.solver->enable_leaflet_contact(std::move(surface_of_node));
  } else {
    setup.notes.push_back(fmt::format("leaflet-leaflet contact not needed: {} leaflet node set(s)", leaflets));
  }
  return setup;
}

}  // namespace valvefsi::solid
