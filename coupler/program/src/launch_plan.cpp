#include "valvefsi/coupler/launch_plan.hpp"

#include <fmt/format.h>

#include "valvefsi/case/case_loader.hpp"
#include "valvefsi/coupling/endpoint.hpp"

namespace valvefsi::coupler {

namespace {

std::string json_string(const std::string& text) {
  std::string out = "\"";
  for (const char c : text) {
    switch (c) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\n': out += "\\n"; break;
      case '\t': out += "\\t"; break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          out += fmt::format("\\u{:04x}", static_cast<unsigned char>(c));
        } else {
          out += c;
        }
    }
  }
  return out + "\"";
}

std::string program_json(const std::filesystem::path& case_file, const std::string& executable,
                         const google::protobuf::RepeatedPtrField<std::string>& arguments) {
  const std::string resolved =
      executable.find('/') == std::string::npos ? executable : resolve_case_path(case_file, executable).string();
  std::string args;
  for (const auto& argument : arguments) args += (args.empty() ? "" : ", ") + json_string(argument);
  return fmt::format("{{\"executable\": {}, \"arguments\": [{}]}}", json_string(resolved), args);
}

}  // namespace

std::string launch_plan_json(const std::filesystem::path& case_file, const cases::Case& run_case,
                             const std::filesystem::path& output_dir) {
  const auto& coupling = run_case.coupling();
  const google::protobuf::RepeatedPtrField<std::string> no_arguments;
  return fmt::format(
      "{{\"output_dir\": {}, \"endpoint\": {}, \"fe_only\": {}, \"fluid\": {}, \"solid\": {}, \"coupler\": {}}}",
      json_string(output_dir.string()), json_string(coupling::resolve_endpoint(coupling.endpoint(), output_dir)),
      run_case.run().fe_only() ? "true" : "false",
      program_json(case_file, coupling.fluid_executable(), coupling.fluid_arguments()),
      program_json(case_file, coupling.solid_executable(), coupling.solid_arguments()),
      program_json(case_file, coupling.coupler_executable(), no_arguments));
}

}  // namespace valvefsi::coupler
