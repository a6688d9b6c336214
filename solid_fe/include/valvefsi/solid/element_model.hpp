#pragma once
// What the explicit integrator (explicit_solver.hpp) needs from an element family: lumped
// masses, fixed nodes, internal forces with a stable-step bound, the follower-pressure load and
// the per-element output fields. Implemented by the shell triangle (shell_elements.hpp) and the
// 8-node brick (hexahedron_elements.hpp); docs/solid_fe.md, "One integrator, two element models".
#include <cstdint>
#include <limits>
#include <vector>

#include <Eigen/Core>

namespace valvefsi::solid {

struct ShellModel;

enum class ElementFamily { shell, hexahedron };

struct InternalForceResult {
  double strain_energy = 0;     // hyperelastic energy of the state (J)
  double hourglass_energy = 0;  // stored in hourglass control (J); 0 for elements without it
  double min_step = std::numeric_limits<double>::infinity();  // smallest element critical step, no safety (s)
  std::int64_t critical_element = -1;                          // the element that sets it
};

class ElementModel {
 public:
  virtual ~ElementModel() = default;
  virtual const char* family() const = 0;  // "shell" or "hexahedron", for messages
  virtual const Eigen::Matrix3Xd& reference_positions() const = 0;
  virtual const Eigen::VectorXd& nodal_mass() const = 0;       // lumped (kg)
  virtual const std::vector<std::uint8_t>& fixed() const = 0;  // 1 for fixed nodes
  virtual std::int64_t num_elements() const = 0;
  // Per node: the offset of the contact surface from the node (half the shell thickness; 0 for
  // bricks, whose nodes lie on the real surfaces).
  virtual Eigen::VectorXd contact_half_thickness() const = 0;
  virtual bool has_hourglass_forces() const { return false; }
  // Internal force at x into `out` (and its hourglass part into `hourglass` when given and the
  // family has one); with `estimate_step` the smallest element step bound. Throws
  // MaterialStateError("element <e>: ...") naming the element.
  virtual InternalForceResult internal_force(const Eigen::Matrix3Xd& x, bool estimate_step, Eigen::Matrix3Xd& out,
                                             Eigen::Matrix3Xd* hourglass) = 0;
  // Adds the follower pressure dp (Pa) on the family's loaded surface, pushing toward +normal.
  virtual void add_pressure_force(const Eigen::Matrix3Xd& x, double dp, Eigen::Matrix3Xd& forces) const = 0;
  // Maximum principal Cauchy stress (Pa) and logarithmic strain per element (NaN where the state
  // cannot be evaluated).
  virtual void element_fields(const Eigen::Matrix3Xd& x, Eigen::VectorXd& max_principal_stress,
                              Eigen::VectorXd& max_principal_log_strain) const = 0;
  // The triangle surface leaflet-leaflet contact works on (shells only; nullptr otherwise).
  virtual const ShellModel* contact_surface() const { return nullptr; }
};

}  // namespace valvefsi::solid
