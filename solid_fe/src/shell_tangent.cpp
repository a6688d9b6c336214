// Tangents of the shell triangle for implicit dynamics (docs/solid_fe.md, "Implicit dynamics").
// The internal-force tangent is a forward difference, element by element, of the element's own
// exact force (shell_forces.hpp): its force depends on at most six nodes (its three and the three
// across its interior edges), so 18 perturbed element evaluations give its 18 x 18 block. Why a
// difference and not the analytic tangent: the hinge angles' second derivatives and the
// plane-stress condensation through the thickness would be a new, separately verified code path;
// the difference reuses the verified forces and is checked against the global force difference
// in tests/solid_fe/implicit_dynamics_test.cpp. The follower-pressure tangent is analytic.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <variant>
#include <vector>

#include <omp.h>

#include "valvefsi/solid/shell_elements.hpp"
#include "valvefsi/solid/shell_forces.hpp"

namespace valvefsi::solid {
namespace {

// The nodes an element's force depends on: its own three, then the opposite nodes of interior edges.
int element_patch(const ShellElement& el, std::array<std::int32_t, 6>& nodes) {
  int count = 0;
  for (const auto a : el.nodes) nodes[static_cast<std::size_t>(count++)] = a;
  for (int i = 0; i < 3; ++i) {
    if (el.edge_kind[i] != EdgeKind::interior || el.opposite[i] < 0) continue;
    const std::int32_t o = el.opposite[i];
    if (std::find(nodes.begin(), nodes.begin() + count, o) == nodes.begin() + count) {
      nodes[static_cast<std::size_t>(count++)] = o;
    }
  }
  return count;
}

Eigen::Matrix3d cross_matrix(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

}  // namespace

void ShellElements::internal_force_tangent(const Eigen::Matrix3Xd& x, std::vector<NodeBlock>& blocks) {
  const auto num_elements = static_cast<std::int64_t>(model_.elements.size());
  const int threads = num_elements >= kMinElementsForThreads ? omp_get_max_threads() : 1;
  std::vector<std::vector<NodeBlock>> thread_blocks(static_cast<std::size_t>(threads));
  std::string error;
  std::visit(
      [&](const auto& law) {
#pragma omp parallel num_threads(threads)
        {
          std::vector<NodeBlock>& out = thread_blocks[static_cast<std::size_t>(omp_get_thread_num())];
          Eigen::Matrix3Xd xs = x;
          Eigen::Matrix3Xd f = Eigen::Matrix3Xd::Zero(3, x.cols());
          Eigen::Matrix<double, 18, 18> k;
          Eigen::Matrix<double, 18, 1> f0;
          std::array<std::int32_t, 6> nodes{};
          const auto element_force = [&](const ShellElement& el, int count, Eigen::Matrix<double, 18, 1>& into) {
            for (int a = 0; a < count; ++a) f.col(nodes[static_cast<std::size_t>(a)]).setZero();
            add_element_internal_force(model_, el, law, xs, f, false);
            for (int a = 0; a < count; ++a) into.segment<3>(3 * a) = f.col(nodes[static_cast<std::size_t>(a)]);
          };
#pragma omp for schedule(static)
          for (std::int64_t e = 0; e < num_elements; ++e) {
            const ShellElement& el = model_.elements[static_cast<std::size_t>(e)];
            const int count = element_patch(el, nodes);
            try {
              element_force(el, count, f0);
              // A relative perturbation of 1e-7 of the element size: truncation ~1e-7 x the
              // stiffening rate, round-off ~1e-9 of the force.
              const double h = 1e-7 * std::sqrt(el.area);
              Eigen::Matrix<double, 18, 1> fp;
              for (int b = 0; b < count; ++b) {
                for (int d = 0; d < 3; ++d) {
                  const auto node = nodes[static_cast<std::size_t>(b)];
                  const double saved = xs(d, node);
                  xs(d, node) = saved + h;
                  element_force(el, count, fp);
                  xs(d, node) = saved;
                  k.col(3 * b + d).head(3 * count) = (fp.head(3 * count) - f0.head(3 * count)) / h;
                }
              }
            } catch (const MaterialStateError& ex) {
#pragma omp critical(valvefsi_solid_tangent_error)
              if (error.empty()) error = fmt::format("element {}: {}", e, ex.what());
              continue;
            }
            for (int a = 0; a < count; ++a) {
              for (int b = 0; b < count; ++b) {
                out.push_back({nodes[static_cast<std::size_t>(a)], nodes[static_cast<std::size_t>(b)],
                               k.block<3, 3>(3 * a, 3 * b)});
              }
            }
          }
        }
      },
      material_);
  if (!error.empty()) throw MaterialStateError(error);
  blocks.clear();
  for (const auto& tb : thread_blocks) blocks.insert(blocks.end(), tb.begin(), tb.end());
}

void ShellElements::add_pressure_tangent(const Eigen::Matrix3Xd& x, double dp, std::vector<NodeBlock>& blocks) const {
  if (dp == 0.0) return;
  // f_b = dp/3 * A, A = 1/2 (x1 - x0) x (x2 - x0) for every node b; dA/dx_a = 1/2 [x_{a+2} - x_{a+1}]_x.
  for (const std::int64_t e : pressure_elements_) {
    const auto& nodes = model_.elements[static_cast<std::size_t>(e)].nodes;
    for (int a = 0; a < 3; ++a) {
      const Eigen::Matrix3d d = (dp / 6.0) * cross_matrix(x.col(nodes[(a + 2) % 3]) - x.col(nodes[(a + 1) % 3]));
      for (int b = 0; b < 3; ++b) blocks.push_back({nodes[static_cast<std::size_t>(b)], nodes[static_cast<std::size_t>(a)], d});
    }
  }
}

}  // namespace valvefsi::solid
