#include "valvefsi/case/case_loader.hpp"

#include <google/protobuf/descriptor.h>
#include <google/protobuf/io/tokenizer.h>
#include <google/protobuf/text_format.h>

#include <cmath>
#include <fmt/format.h>
#include <fstream>
#include <limits>
#include <optional>
#include <regex>
#include <sstream>
#include <vector>

#include "field_limits.pb.h"

namespace valvefsi {
namespace {

namespace pb = google::protobuf;

// Collects the parser's complaints as "file:line:column: message" (protobuf counts from 0).
class CollectingErrors : public pb::io::ErrorCollector {
 public:
  explicit CollectingErrors(std::string source) : source_(std::move(source)) {}
  void AddError(int line, pb::io::ColumnNumber column, const std::string& message) override {
    errors_.push_back(fmt::format("{}:{}:{}: {}", source_, line + 1, column + 1,
                                  with_allowed_fields(message)));
  }
  void AddWarning(int line, pb::io::ColumnNumber column, const std::string& message) override {
    AddError(line, column, message);
  }
  [[nodiscard]] const std::vector<std::string>& errors() const { return errors_; }

 private:
  // protobuf says which message lacks a field; the user also needs what it does have.
  static std::string with_allowed_fields(const std::string& message) {
    static const std::regex unknown_field(R"re(Message type "([\w.]+)" has no field named "(\w+)")re");
    std::smatch match;
    if (!std::regex_search(message, match, unknown_field)) return message;
    const pb::Descriptor* type =
        pb::DescriptorPool::generated_pool()->FindMessageTypeByName(match[1].str());
    if (type == nullptr) return message;
    std::string names;
    for (int i = 0; i < type->field_count(); ++i) {
      names += (i == 0 ? "" : ", ") + type->field(i)->name();
    }
    return fmt::format("unknown field '{}' in {}; allowed fields: {}", match[2].str(),
                       type->name(), names.empty() ? "(none yet)" : names);
  }
  std::string source_;
  std::vector<std::string> errors_;
};

const valvefsi::FieldLimits* limits_of(const pb::FieldDescriptor& field) {
  if (!field.options().HasExtension(valvefsi::limits)) return nullptr;
  return &field.options().GetExtension(valvefsi::limits);
}

std::string describe_allowed(const valvefsi::FieldLimits& limits) {
  std::string text;
  if (limits.has_min() && limits.has_max()) {
    text = fmt::format("{} {} value {} {}", limits.min(), limits.min_exclusive() ? "<" : "<=",
                       limits.max_exclusive() ? "<" : "<=", limits.max());
  } else if (limits.has_min()) {
    text = fmt::format("value {} {}", limits.min_exclusive() ? ">" : ">=", limits.min());
  } else if (limits.has_max()) {
    text = fmt::format("value {} {}", limits.max_exclusive() ? "<" : "<=", limits.max());
  } else {
    text = "any value";
  }
  return text;
}

bool within(double value, const valvefsi::FieldLimits& limits) {
  if (!std::isfinite(value)) return false;
  if (limits.has_min() && (limits.min_exclusive() ? value <= limits.min() : value < limits.min())) {
    return false;
  }
  if (limits.has_max() && (limits.max_exclusive() ? value >= limits.max() : value > limits.max())) {
    return false;
  }
  return true;
}

bool is_numeric(const pb::FieldDescriptor& field) {
  switch (field.cpp_type()) {
    case pb::FieldDescriptor::CPPTYPE_INT32:
    case pb::FieldDescriptor::CPPTYPE_INT64:
    case pb::FieldDescriptor::CPPTYPE_UINT32:
    case pb::FieldDescriptor::CPPTYPE_UINT64:
    case pb::FieldDescriptor::CPPTYPE_DOUBLE:
    case pb::FieldDescriptor::CPPTYPE_FLOAT:
      return true;
    default:
      return false;
  }
}

double numeric_value(const pb::Message& message, const pb::FieldDescriptor& field, int index) {
  const pb::Reflection& r = *message.GetReflection();
  const bool repeated = field.is_repeated();
  switch (field.cpp_type()) {
    case pb::FieldDescriptor::CPPTYPE_INT32:
      return repeated ? r.GetRepeatedInt32(message, &field, index) : r.GetInt32(message, &field);
    case pb::FieldDescriptor::CPPTYPE_INT64:
      return static_cast<double>(repeated ? r.GetRepeatedInt64(message, &field, index)
                                          : r.GetInt64(message, &field));
    case pb::FieldDescriptor::CPPTYPE_UINT32:
      return repeated ? r.GetRepeatedUInt32(message, &field, index) : r.GetUInt32(message, &field);
    case pb::FieldDescriptor::CPPTYPE_UINT64:
      return static_cast<double>(repeated ? r.GetRepeatedUInt64(message, &field, index)
                                          : r.GetUInt64(message, &field));
    case pb::FieldDescriptor::CPPTYPE_FLOAT:
      return repeated ? r.GetRepeatedFloat(message, &field, index) : r.GetFloat(message, &field);
    default:
      return repeated ? r.GetRepeatedDouble(message, &field, index) : r.GetDouble(message, &field);
  }
}

void set_numeric(pb::Message& message, const pb::FieldDescriptor& field, double value) {
  const pb::Reflection& r = *message.GetReflection();
  switch (field.cpp_type()) {
    case pb::FieldDescriptor::CPPTYPE_INT32:
      r.SetInt32(&message, &field, static_cast<std::int32_t>(value));
      break;
    case pb::FieldDescriptor::CPPTYPE_INT64:
      r.SetInt64(&message, &field, static_cast<std::int64_t>(value));
      break;
    case pb::FieldDescriptor::CPPTYPE_UINT32:
      r.SetUInt32(&message, &field, static_cast<std::uint32_t>(value));
      break;
    case pb::FieldDescriptor::CPPTYPE_UINT64:
      r.SetUInt64(&message, &field, static_cast<std::uint64_t>(value));
      break;
    case pb::FieldDescriptor::CPPTYPE_FLOAT:
      r.SetFloat(&message, &field, static_cast<float>(value));
      break;
    default:
      r.SetDouble(&message, &field, value);
  }
}

// Walks a message and its present sub-messages, checking limits and filling defaults.
class LimitChecker {
 public:
  explicit LimitChecker(std::string source) : source_(std::move(source)) {}

  void check(pb::Message& message, const pb::TextFormat::ParseInfoTree* tree,
             const std::string& path, int parent_line) {
    const pb::Descriptor& type = *message.GetDescriptor();
    const pb::Reflection& r = *message.GetReflection();
    for (int i = 0; i < type.field_count(); ++i) {
      const pb::FieldDescriptor& field = *type.field(i);
      const std::string name = path.empty() ? field.name() : path + "." + field.name();
      if (field.cpp_type() == pb::FieldDescriptor::CPPTYPE_MESSAGE) {
        check_nested(message, field, tree, name, parent_line);
        continue;
      }
      const valvefsi::FieldLimits* limits = limits_of(field);
      if (limits == nullptr) continue;
      if (field.is_repeated()) {
        const int n = r.FieldSize(message, &field);
        if (n == 0 && limits->required()) missing(name, *limits, parent_line);
        for (int k = 0; is_numeric(field) && k < n; ++k) {
          const double value = numeric_value(message, field, k);
          if (!within(value, *limits)) {
            out_of_range(fmt::format("{}[{}]", name, k), value, *limits, line_of(tree, field, k));
          }
        }
        continue;
      }
      if (!r.HasField(message, &field)) {
        if (limits->required()) {
          missing(name, *limits, parent_line);
        } else if (limits->has_default_value() && is_numeric(field)) {
          set_numeric(message, field, limits->default_value());
        } else if (limits->has_default_text() &&
                   field.cpp_type() == pb::FieldDescriptor::CPPTYPE_STRING) {
          r.SetString(&message, &field, limits->default_text());
        }
        continue;
      }
      if (is_numeric(field)) {
        const double value = numeric_value(message, field, -1);
        if (!within(value, *limits)) out_of_range(name, value, *limits, line_of(tree, field, -1));
      } else if (field.cpp_type() == pb::FieldDescriptor::CPPTYPE_STRING && limits->required() &&
                 r.GetString(message, &field).empty()) {
        errors_.push_back(fmt::format("{}:{}: field '{}' is empty; a value is required", source_,
                                      line_of(tree, field, -1), name));
      }
    }
  }

  [[nodiscard]] const std::vector<std::string>& errors() const { return errors_; }

 private:
  void check_nested(pb::Message& message, const pb::FieldDescriptor& field,
                    const pb::TextFormat::ParseInfoTree* tree, const std::string& name,
                    int parent_line) {
    const pb::Reflection& r = *message.GetReflection();
    if (field.is_repeated()) {
      for (int k = 0; k < r.FieldSize(message, &field); ++k) {
        check(*r.MutableRepeatedMessage(&message, &field, k),
              tree ? tree->GetTreeForNested(&field, k) : nullptr, fmt::format("{}[{}]", name, k),
              line_or(tree, field, k, parent_line));
      }
      return;
    }
    // Only sections the case writes are checked: an FE-only case has no fluid section, and the
    // program that needs a section says so when it is absent.
    if (!r.HasField(message, &field)) return;
    check(*r.MutableMessage(&message, &field), tree ? tree->GetTreeForNested(&field, -1) : nullptr,
          name, line_or(tree, field, -1, parent_line));
  }

  static int line_or(const pb::TextFormat::ParseInfoTree* tree, const pb::FieldDescriptor& field,
                     int index, int fallback) {
    if (tree == nullptr) return fallback;
    const pb::TextFormat::ParseLocation location = tree->GetLocation(&field, index);
    return location.line >= 0 ? location.line + 1 : fallback;
  }
  static int line_of(const pb::TextFormat::ParseInfoTree* tree, const pb::FieldDescriptor& field,
                     int index) {
    return line_or(tree, field, index, 0);
  }

  void missing(const std::string& name, const valvefsi::FieldLimits& limits, int parent_line) {
    errors_.push_back(fmt::format("{}:{}: required field '{}' is missing (allowed: {})", source_,
                                  parent_line, name, describe_allowed(limits)));
  }
  void out_of_range(const std::string& name, double value, const valvefsi::FieldLimits& limits,
                    int line) {
    errors_.push_back(fmt::format("{}:{}: field '{}' = {} is out of range; allowed: {}", source_,
                                  line, name, value, describe_allowed(limits)));
  }

  std::string source_;
  std::vector<std::string> errors_;
};

std::string join_lines(const std::vector<std::string>& lines) {
  std::string text;
  for (const std::string& line : lines) text += (text.empty() ? "" : "\n") + line;
  return text;
}

}  // namespace

void apply_field_limits(google::protobuf::Message& message, const std::string& source_name,
                        const std::string& path_prefix) {
  LimitChecker checker(source_name);
  checker.check(message, nullptr, path_prefix, 0);
  if (!checker.errors().empty()) throw CaseError(join_lines(checker.errors()));
}

cases::Case parse_case_text(std::string_view text, const std::string& source_name) {
  cases::Case parsed;
  CollectingErrors collector(source_name);
  pb::TextFormat::ParseInfoTree tree;
  pb::TextFormat::Parser parser;
  parser.RecordErrorsTo(&collector);
  parser.WriteLocationsTo(&tree);
  if (!parser.ParseFromString(std::string(text), &parsed)) {
    if (collector.errors().empty()) throw CaseError(source_name + ": cannot parse the case file");
    throw CaseError(join_lines(collector.errors()));
  }
  LimitChecker checker(source_name);
  checker.check(parsed, &tree, "", 1);
  if (!checker.errors().empty()) throw CaseError(join_lines(checker.errors()));
  return parsed;
}

cases::Case load_case(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) {
    throw CaseError(fmt::format("cannot open case file '{}': {}", path.string(),
                                std::filesystem::exists(path) ? "not readable" : "no such file"));
  }
  std::ostringstream text;
  text << in.rdbuf();
  return parse_case_text(text.str(), path.string());
}

std::filesystem::path resolve_case_path(const std::filesystem::path& case_file,
                                        const std::string& value) {
  const std::filesystem::path given(value);
  if (given.is_absolute()) return given;
  return case_file.parent_path() / given;
}

}  // namespace valvefsi
