#include "valvefsi/coupling/model_problems/in_process_coupling.hpp"

#include "parameter_checks.hpp"

#include <string>

namespace valvefsi::coupling::model {

CouplingScheme parse_coupling_scheme(std::string_view name) {
  if (name == "serial-explicit") return CouplingScheme::serial_explicit;
  if (name == "parallel-explicit") return CouplingScheme::parallel_explicit;
  if (name == "implicit") return CouplingScheme::implicit;
  throw std::invalid_argument("unknown coupling scheme '" + std::string(name) +
                              "'; allowed: \"serial-explicit\", \"parallel-explicit\", \"implicit\"");
}

namespace {

bool out_of_bounds(const Eigen::VectorXd& motion, double bound) {
  return !motion.allFinite() || motion.cwiseAbs().maxCoeff() > bound;
}

}  // namespace

CouplingRun run_in_process(ModelParticipant& fluid, ModelParticipant& solid, const CouplingLoopOptions& options) {
  require_positive("coupling loop", "window", options.window);
  require_positive("coupling loop", "tolerance", options.tolerance);
  if (options.max_iterations < 1) parameter_error("coupling loop", "max_iterations", options.max_iterations, ">= 1");
  const auto acceleration =
      options.scheme == CouplingScheme::implicit ? make_acceleration(options.acceleration) : nullptr;

  CouplingRun run;
  Eigen::VectorXd motion = solid.current_data();
  Eigen::VectorXd loads = fluid.current_data();
  for (int n = 0; n < options.windows; ++n) {
    WindowRecord record;
    switch (options.scheme) {
      case CouplingScheme::serial_explicit:
        loads = fluid.advance(options.window, motion);
        motion = solid.advance(options.window, loads);
        break;
      case CouplingScheme::parallel_explicit: {
        const Eigen::VectorXd new_loads = fluid.advance(options.window, motion);
        motion = solid.advance(options.window, loads);
        loads = new_loads;
        break;
      }
      case CouplingScheme::implicit: {
        fluid.save_checkpoint();
        solid.save_checkpoint();
        acceleration->begin_window();
        Eigen::VectorXd input = motion;
        bool converged = false;
        for (int k = 1; k <= options.max_iterations; ++k) {
          loads = fluid.advance(options.window, input);
          motion = solid.advance(options.window, loads);
          record.iterations = k;
          record.residual = relative_residual(input, motion);
          if (record.residual < options.tolerance) {
            converged = true;
            break;
          }
          if (k == options.max_iterations || out_of_bounds(motion, options.divergence_bound)) break;
          input = acceleration->next_input(input, motion);
          fluid.restore_checkpoint();
          solid.restore_checkpoint();
        }
        if (converged) {
          acceleration->end_window();
        } else {
          run.all_windows_converged = false;
        }
        break;
      }
    }
    record.time = solid.time();
    record.motion = motion;
    record.loads = loads;
    run.windows.push_back(record);
    if (out_of_bounds(motion, options.divergence_bound)) {
      run.diverged = true;
      break;
    }
    if (!run.all_windows_converged) break;
  }
  return run;
}

}  // namespace valvefsi::coupling::model
