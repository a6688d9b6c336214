#pragma once
// The rotation-free shell triangle as an element model of the explicit integrator
// (element_model.hpp): forces, step bound and output fields from shell_forces.hpp, follower
// pressure dp * (current area vector) / 3 per node on the loaded triangles.
#include <cstdint>
#include <vector>

#include "valvefsi/solid/element_model.hpp"
#include "valvefsi/solid/hinge_angle.hpp"
#include "valvefsi/solid/material.hpp"
#include "valvefsi/solid/shell_model.hpp"

namespace valvefsi::solid {

class ShellElements final : public ElementModel {
 public:
  ShellElements(ShellModel model, Material material);

  const char* family() const override { return "shell"; }
  const Eigen::Matrix3Xd& reference_positions() const override { return model_.reference_positions; }
  const Eigen::VectorXd& nodal_mass() const override { return model_.nodal_mass; }
  const std::vector<std::uint8_t>& fixed() const override { return model_.fixed; }
  std::int64_t num_elements() const override { return static_cast<std::int64_t>(model_.elements.size()); }
  Eigen::VectorXd contact_half_thickness() const override;
  InternalForceResult internal_force(const Eigen::Matrix3Xd& x, bool estimate_step, Eigen::Matrix3Xd& out,
                                     Eigen::Matrix3Xd* hourglass) override;
  void add_pressure_force(const Eigen::Matrix3Xd& x, double dp, Eigen::Matrix3Xd& forces) const override;
  void element_fields(const Eigen::Matrix3Xd& x, Eigen::VectorXd& max_principal_stress,
                      Eigen::VectorXd& max_principal_log_strain) const override;
  const ShellModel* contact_surface() const override { return &model_; }
  // Element-level forward-difference tangent of the exact element forces (shell_tangent.cpp).
  void internal_force_tangent(const Eigen::Matrix3Xd& x, std::vector<NodeBlock>& blocks) override;
  void add_pressure_tangent(const Eigen::Matrix3Xd& x, double dp, std::vector<NodeBlock>& blocks) const override;

  // Triangles the pressure loads (all when empty); throws std::invalid_argument for a bad index.
  void set_pressure_elements(std::vector<std::int64_t> elements);
  const ShellModel& model() const { return model_; }
  const Material& material() const { return material_; }

 private:
  ShellModel model_;
  Material material_;
  std::vector<std::int64_t> pressure_elements_;
  std::vector<HingeSide> hinge_sides_;           // 3 per element, refreshed at each evaluation
};

}  // namespace valvefsi::solid
