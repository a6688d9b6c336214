#include "valvefsi/solid/energy_growth_report.hpp"

#include <algorithm>

#include <fmt/format.h>
#include <fmt/ranges.h>

namespace valvefsi::solid {
namespace {

template <std::size_t N>
std::string hottest_of(const std::vector<std::array<std::int64_t, N>>& elements, const ExplicitSolver& solver,
                       std::int64_t node) {
  const Eigen::Matrix3Xd& v = solver.state().velocity;
  const Eigen::VectorXd& m = solver.elements().nodal_mass();
  const auto kinetic = [&](std::int64_t i) { return 0.5 * m(i) * v.col(i).squaredNorm(); };
  std::int64_t best = -1;
  double best_energy = -1.0;
  for (std::size_t e = 0; e < elements.size(); ++e) {
    const auto& nodes = elements[e];
    if (std::find(nodes.begin(), nodes.end(), node) == nodes.end()) continue;
    double sum = 0.0;
    for (const auto i : nodes) sum += kinetic(i);
    if (sum > best_energy) {
      best_energy = sum;
      best = static_cast<std::int64_t>(e);
    }
  }
  if (best < 0) return "no element";
  const double total = std::max(solver.state().energy.kinetic, 1e-300);
  return fmt::format("element {} (nodes {}, {:.1f} % of the kinetic energy)", best,
                     fmt::join(elements[static_cast<std::size_t>(best)], " "), 100.0 * best_energy / total);
}

}  // namespace

std::string kinetic_energy_element(const Mesh& mesh, ElementFamily family, const ExplicitSolver& solver,
                                   std::int64_t hottest_node) {
  return family == ElementFamily::hexahedron ? hottest_of(mesh.hexahedra, solver, hottest_node)
                                             : hottest_of(mesh.triangles, solver, hottest_node);
}

}  // namespace valvefsi::solid
