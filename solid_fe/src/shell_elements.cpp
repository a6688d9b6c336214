#include "valvefsi/solid/shell_elements.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

#include <fmt/format.h>
#include <omp.h>

#include "valvefsi/solid/material_error.hpp"
#include "valvefsi/solid/shell_forces.hpp"

namespace valvefsi::solid {
ShellElements::ShellElements(ShellModel model, Material material)
    : model_(std::move(model)), material_(std::move(material)) {
  set_pressure_elements({});
}

Eigen::VectorXd ShellElements::contact_half_thickness() const {
  Eigen::VectorXd half = Eigen::VectorXd::Zero(model_.reference_positions.cols());
  for (const auto& el : model_.elements) {
    for (const auto a : el.nodes) half(a) = std::max(half(a), 0.5 * el.thickness);
  }
  return half;
}

void ShellElements::set_pressure_elements(std::vector<std::int64_t> elements) {
  if (elements.empty()) {
    elements.resize(model_.elements.size());
    for (std::size_t e = 0; e < elements.size(); ++e) elements[e] = static_cast<std::int64_t>(e);
  }
  for (const std::int64_t e : elements) {
    if (e < 0 || e >= static_cast<std::int64_t>(model_.elements.size())) {
      throw std::invalid_argument(fmt::format("solid: pressure element {} does not exist", e));
    }
  }
  pressure_elements_ = std::move(elements);
}

InternalForceResult ShellElements::internal_force(const Eigen::Matrix3Xd& x, bool estimate_step,
                                                  Eigen::Matrix3Xd& out, Eigen::Matrix3Xd* /*hourglass*/) {
  const auto num_elements = static_cast<std::int64_t>(model_.elements.size());
  hinge_sides_.resize(static_cast<std::size_t>(3 * num_elements));
  HingeSide* sides = hinge_sides_.data();
  return std::visit(
      [&](const auto& law) {
        return accumulate_element_forces(
            "element", num_elements, [&](std::int64_t e) { own_hinge_sides(model_, e, x, sides); },
            [&](std::int64_t e, Eigen::Matrix3Xd& f, Eigen::Matrix3Xd&) {
              const ElementResult r = add_element_internal_force(model_, model_.elements[static_cast<std::size_t>(e)],
                                                                 law, x, f, estimate_step, sides, e);
              return ElementContribution{r.strain_energy, 0.0, r.stable_step};
            },
            out, nullptr);
      },
      material_);
}

void ShellElements::add_pressure_force(const Eigen::Matrix3Xd& x, double dp, Eigen::Matrix3Xd& f) const {
  for (const std::int64_t e : pressure_elements_) {
    const auto& nodes = model_.elements[static_cast<std::size_t>(e)].nodes;
    const Eigen::Vector3d area_vector =
        0.5 * (x.col(nodes[1]) - x.col(nodes[0])).cross(x.col(nodes[2]) - x.col(nodes[0]));
    const Eigen::Vector3d share = (dp / 3.0) * area_vector;
    for (int a = 0; a < 3; ++a) f.col(nodes[a]) += share;
  }
}

void ShellElements::element_fields(const Eigen::Matrix3Xd& x, Eigen::VectorXd& max_principal_stress,
                                   Eigen::VectorXd& max_principal_log_strain) const {
  const auto num_elements = static_cast<Eigen::Index>(model_.elements.size());
  max_principal_stress.resize(num_elements);
  max_principal_log_strain.resize(num_elements);
  std::visit(
      [&](const auto& law) {
#pragma omp parallel for schedule(static) if (num_elements >= kMinElementsForThreads)
        for (Eigen::Index e = 0; e < num_elements; ++e) {
          try {
            const ElementFieldValues v = element_field_values(model_, model_.elements[static_cast<std::size_t>(e)], law, x);
            max_principal_stress(e) = v.max_principal_stress;
            max_principal_log_strain(e) = v.max_principal_log_strain;
          } catch (const MaterialStateError&) {
            // Output of a state the solver could not evaluate: mark it rather than stop.
            max_principal_stress(e) = std::numeric_limits<double>::quiet_NaN();
            max_principal_log_strain(e) = std::numeric_limits<double>::quiet_NaN();
          }
        }
      },
      material_);
}

}  // namespace valvefsi::solid
