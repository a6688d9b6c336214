#pragma once
// The contract of a model "solver" with a known answer: it advances one coupling window given
// its partner's interface data and returns its own, and can save and restore its state so an
// implicit scheme can repeat a window. A stand-in participant is a thin wrapper around it.
//
// Data layout of the piston models: a solid sends motion [displacement (m), velocity (m/s)]
// of the piston; a fluid sends loads [force on the piston along +x (N)].

#include <Eigen/Core>

namespace valvefsi::coupling::model {

// Checks a restart's value count; throws std::invalid_argument naming the model.
void require_state_size(const char* model, const Eigen::VectorXd& values, Eigen::Index expected);

class ModelParticipant {
 public:
  virtual ~ModelParticipant() = default;
  // Own interface data at the current time, before any window (what the partner reads first).
  virtual Eigen::VectorXd current_data() const = 0;
  // Pre: window > 0, partner_data has the partner's size. Post: time() grew by window; returns
  // own interface data at the window's end.
  virtual Eigen::VectorXd advance(double window, const Eigen::VectorXd& partner_data) = 0;
  // save_checkpoint keeps the full state; restore_checkpoint returns to it (any number of times).
  virtual void save_checkpoint() = 0;
  virtual void restore_checkpoint() = 0;
  virtual double time() const = 0;
  // The full state as numbers and back (the stand-ins' restart files). load_state_values
  // throws std::invalid_argument when the count does not fit this model.
  virtual Eigen::VectorXd state_values() const = 0;
  virtual void load_state_values(const Eigen::VectorXd& values) = 0;
};

}  // namespace valvefsi::coupling::model
