#pragma once
// What the explicit integrator (explicit_solver.hpp) needs from an element family: lumped
// masses, fixed nodes, internal forces with a stable-step bound, the follower-pressure load and
// the per-element output fields. Implemented by the shell triangle (shell_elements.hpp) and the
// 8-node brick (hexahedron_elements.hpp); docs/solid_fe.md, "One integrator, two element models".
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <fmt/format.h>
#include <omp.h>

#include "valvefsi/solid/material_error.hpp"

namespace valvefsi::solid {

struct ShellModel;

enum class ElementFamily { shell, hexahedron };

struct InternalForceResult {
  double strain_energy = 0;     // hyperelastic energy of the state (J)
  double hourglass_energy = 0;  // stored in hourglass control (J); 0 for elements without it
  double min_step = std::numeric_limits<double>::infinity();  // smallest element critical step, no safety (s)
  std::int64_t critical_element = -1;                          // the element that sets it
};

// One element's share of an internal-force evaluation (its forces go into the thread's arrays).
struct ElementContribution {
  double strain_energy = 0;
  double hourglass_energy = 0;
  double stable_step = std::numeric_limits<double>::infinity();  // its critical step, no safety (s)
};

// One 3x3 block of a tangent: d(force at node `row`) / d(position of node `col`).
struct NodeBlock {
  std::int32_t row = 0;
  std::int32_t col = 0;
  Eigen::Matrix3d k = Eigen::Matrix3d::Zero();
};

// Below this many elements thread start-up costs more than it saves.
inline constexpr std::int64_t kMinElementsForThreads = 1000;

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
  // Implicit dynamics (implicit_dynamics.cpp): the tangent d f_int / dx at x as node blocks, the
  // same blocks in the same order at every call (the sparse pattern is analysed once).
  virtual void internal_force_tangent(const Eigen::Matrix3Xd& /*x*/, std::vector<NodeBlock>& /*blocks*/) {
    throw std::invalid_argument(fmt::format("solid: implicit time integration is not available for {} elements "
                                            "(allowed: shell)", family()));
  }
  // Appends d f_pressure / dx of the follower pressure dp (Pa) at x (no blocks when dp = 0).
  virtual void add_pressure_tangent(const Eigen::Matrix3Xd& /*x*/, double /*dp*/, std::vector<NodeBlock>& /*blocks*/) const {
    throw std::invalid_argument(fmt::format("solid: implicit time integration is not available for {} elements "
                                            "(allowed: shell)", family()));
  }
  // The triangle surface leaflet-leaflet contact works on (shells only; nullptr otherwise).
  virtual const ShellModel* contact_surface() const { return nullptr; }

 protected:
  // The element loop every family shares: elements in parallel (threads from
  // kMinElementsForThreads elements on), each thread summing forces into its own arrays, which
  // are added into `out` (and `hourglass` when given) afterwards. `prepare(e)` runs over all
  // elements first (a barrier follows: e.g. the shell's shared hinge sides), then
  // `element(e, forces, hourglass_forces)` returns the element's ElementContribution. A
  // MaterialStateError is rethrown after the loop as "<what> <e>: <message>" (the first one).
  template <class Prepare, class Element>
  InternalForceResult accumulate_element_forces(const char* what, std::int64_t num_elements, Prepare&& prepare,
                                                Element&& element, Eigen::Matrix3Xd& out, Eigen::Matrix3Xd* hourglass) {
    const int threads = omp_get_max_threads();
    const Eigen::Index n = reference_positions().cols();
    const bool with_hourglass = has_hourglass_forces();
    if (static_cast<int>(thread_forces_.size()) != threads) {  // (threads that stay idle keep zeros)
      thread_forces_.assign(static_cast<std::size_t>(threads), Eigen::Matrix3Xd::Zero(3, n));
      thread_hourglass_.assign(static_cast<std::size_t>(threads),
                               with_hourglass ? Eigen::Matrix3Xd::Zero(3, n) : Eigen::Matrix3Xd());
    }
    InternalForceResult result;
    std::string error;
#pragma omp parallel if (num_elements >= kMinElementsForThreads)
    {
      const auto t = static_cast<std::size_t>(omp_get_thread_num());
      Eigen::Matrix3Xd& f = thread_forces_[t];
      Eigen::Matrix3Xd& fh = thread_hourglass_[t];
      f.setZero();
      if (with_hourglass) fh.setZero();
      double local_energy = 0.0, local_hourglass = 0.0;
      double local_step = std::numeric_limits<double>::infinity();
      std::int64_t local_critical = -1;
#pragma omp for schedule(static)
      for (std::int64_t e = 0; e < num_elements; ++e) prepare(e);
      // (implicit barrier: everything prepared)
#pragma omp for schedule(static)
      for (std::int64_t e = 0; e < num_elements; ++e) {
        try {
          const ElementContribution r = element(e, f, fh);
          local_energy += r.strain_energy;
          local_hourglass += r.hourglass_energy;
          if (r.stable_step < local_step) {
            local_step = r.stable_step;
            local_critical = e;
          }
        } catch (const MaterialStateError& ex) {
#pragma omp critical(valvefsi_solid_element_error)
          if (error.empty()) error = fmt::format("{} {}: {}", what, e, ex.what());
        }
      }
#pragma omp critical(valvefsi_solid_element_reduce)
      {
        result.strain_energy += local_energy;
        result.hourglass_energy += local_hourglass;
        if (local_step < result.min_step) {
          result.min_step = local_step;
          result.critical_element = local_critical;
        }
      }
    }
    if (!error.empty()) throw MaterialStateError(error);
    if (out.cols() != n) out.resize(3, n);
    out = thread_forces_[0];
    for (std::size_t t = 1; t < thread_forces_.size(); ++t) out += thread_forces_[t];
    if (hourglass != nullptr && with_hourglass) {
      if (hourglass->cols() != n) hourglass->resize(3, n);
      *hourglass = thread_hourglass_[0];
      for (std::size_t t = 1; t < thread_hourglass_.size(); ++t) *hourglass += thread_hourglass_[t];
    }
    return result;
  }

 private:
  std::vector<Eigen::Matrix3Xd> thread_forces_, thread_hourglass_;  // per-thread sums, allocated once
};

}  // namespace valvefsi::solid
