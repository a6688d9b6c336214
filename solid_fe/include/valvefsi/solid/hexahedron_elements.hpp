#pragma once
// The one-point 8-node brick with hourglass control (hexahedron_element.hpp) as an element model
// of the explicit integrator (element_model.hpp), docs/solid_fe-hexahedron.md. Follower pressure
// acts on quadrilateral faces.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "valvefsi/solid/element_model.hpp"
#include "valvefsi/solid/hexahedron_element.hpp"
#include "valvefsi/solid/hexahedron_material.hpp"
#include "valvefsi/solid/mesh.hpp"

namespace valvefsi::solid {

struct HexahedronModelOptions {
  double density = 1100.0;                // kg/m^3
  std::vector<std::int64_t> fixed_nodes;  // nodes held in place
};

struct HexahedronModel {
  std::vector<HexElement> elements;
  Eigen::Matrix3Xd reference_positions;
  Eigen::VectorXd nodal_mass;        // rho V0 / 8 from each brick (kg)
  std::vector<std::uint8_t> fixed;   // 1 for fixed nodes
  double density = 1100.0;
};

// Builds the bricks of `mesh.hexahedra` with their axes; errors name `source`, the element and the value.
HexahedronModel build_hexahedron_model(const Mesh& mesh, const HexahedronModelOptions& options,
                                       const std::string& source);

// A quadrilateral face loaded by pressure: force dp * (area vector by the right-hand rule of its
// node order), distributed consistently over its four nodes.
using PressureFace = std::array<std::int64_t, 4>;

// The ventricular (inflow-side) faces 0-1-2-3 of `elements` (all bricks when empty) that are not
// the aortic face 4-7 of another brick: the outer surface a positive transvalvular pressure
// pushes toward the outflow side. Their right-hand normals point into the brick, i.e. to +normal.
std::vector<PressureFace> ventricular_faces(const Mesh& mesh, const std::vector<std::int64_t>& elements = {});

class HexahedronElements final : public ElementModel {
 public:
  HexahedronElements(HexahedronModel model, SolidMaterial material);

  const char* family() const override { return "hexahedron"; }
  const Eigen::Matrix3Xd& reference_positions() const override { return model_.reference_positions; }
  const Eigen::VectorXd& nodal_mass() const override { return model_.nodal_mass; }
  const std::vector<std::uint8_t>& fixed() const override { return model_.fixed; }
  std::int64_t num_elements() const override { return static_cast<std::int64_t>(model_.elements.size()); }
  Eigen::VectorXd contact_half_thickness() const override {
    return Eigen::VectorXd::Zero(model_.reference_positions.cols());
  }
  bool has_hourglass_forces() const override { return true; }
  InternalForceResult internal_force(const Eigen::Matrix3Xd& x, bool estimate_step, Eigen::Matrix3Xd& out,
                                     Eigen::Matrix3Xd* hourglass) override;
  void add_pressure_force(const Eigen::Matrix3Xd& x, double dp, Eigen::Matrix3Xd& forces) const override;
  // At the element centre, the one integration point (what the reference's one-point bricks report).
  void element_fields(const Eigen::Matrix3Xd& x, Eigen::VectorXd& max_principal_stress,
                      Eigen::VectorXd& max_principal_log_strain) const override;
  // The same on the two faces zeta = -1, +1 (the leaflet's surfaces, bending included), larger of
  // the two, from the trilinear gradient with the sheet's plane-stress law.
  void surface_fields(const Eigen::Matrix3Xd& x, Eigen::VectorXd& max_principal_stress,
                      Eigen::VectorXd& max_principal_log_strain) const;

  // Faces the pressure loads; throws std::invalid_argument for a node that does not exist.
  void set_pressure_faces(std::vector<PressureFace> faces);
  const HexahedronModel& model() const { return model_; }
  const SolidMaterial& material() const { return material_; }

 private:
  void fields(const Eigen::Matrix3Xd& x, Eigen::VectorXd& max_principal_stress,
              Eigen::VectorXd& max_principal_log_strain, bool surfaces) const;

  HexahedronModel model_;
  SolidMaterial material_;
  std::vector<HexModuli> moduli_;  // hourglass moduli per element (the material's small-strain ones)
  std::vector<PressureFace> pressure_faces_;
};

}  // namespace valvefsi::solid
