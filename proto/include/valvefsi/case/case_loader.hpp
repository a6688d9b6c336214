#pragma once
// Loading a case file: protobuf text format checked against the schema in proto/*.proto.
// Every error names the file, the line, the field, the value seen and what is allowed.

#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>

#include "case.pb.h"

namespace valvefsi {

// A case file that cannot be used as written; what() is a complete message for the user.
class CaseError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Reads and checks `path`: syntax, unknown fields (the message lists the allowed ones), the
// (valvefsi.limits) of every field set, required fields of every section present; fills the
// documented defaults of unset fields in present sections. Throws CaseError.
cases::Case load_case(const std::filesystem::path& path);

// As load_case, from text; `source_name` stands for the file name in messages.
cases::Case parse_case_text(std::string_view text, const std::string& source_name);

// Checks and completes any message against its (valvefsi.limits), e.g. a section built in code.
// `source_name` and `path_prefix` ("solid") only shape the messages.
void apply_field_limits(google::protobuf::Message& message, const std::string& source_name,
                        const std::string& path_prefix = "");

// A path written in a case file is relative to the case file's folder unless absolute.
std::filesystem::path resolve_case_path(const std::filesystem::path& case_file,
                                        const std::string& value);

}  // namespace valvefsi
