#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "valvefsi/case/case_loader.hpp"

namespace {

using valvefsi::CaseError;
using valvefsi::parse_case_text;

// Runs the parser and returns the error text it must produce.
std::string error_of(const std::string& text) {
  try {
    parse_case_text(text, "bad.textproto");
  } catch (const CaseError& error) {
    return error.what();
  }
  ADD_FAILURE() << "expected a CaseError for:\n" << text;
  return {};
}

TEST(CaseLoader, FillsDocumentedDefaultsOfPresentSections) {
  const auto parsed = parse_case_text("title: \"t\"\nrun { end_time: 0.8 }\n", "ok.textproto");
  EXPECT_DOUBLE_EQ(parsed.run().end_time(), 0.8);
  EXPECT_EQ(parsed.run().output_dir(), "out");
  EXPECT_DOUBLE_EQ(parsed.run().snapshot_interval(), 0.005);
  EXPECT_EQ(parsed.run().dimension(), 3);
  // Absent sections stay absent: the program that needs one says so.
  EXPECT_FALSE(parsed.has_fluid());
  EXPECT_FALSE(parsed.has_waveform());
}

TEST(CaseLoader, OutOfRangeValueNamesFileLineFieldValueAndRange) {
  const std::string message = error_of("title: \"t\"\nrun {\n  end_time: -2\n}\n");
  EXPECT_NE(message.find("bad.textproto:3:"), std::string::npos) << message;
  EXPECT_NE(message.find("'run.end_time' = -2"), std::string::npos) << message;
  EXPECT_NE(message.find("0 < value <= 100"), std::string::npos) << message;
}

TEST(CaseLoader, IntegerLimitsAreChecked) {
  const std::string message = error_of("run { end_time: 1 dimension: 4 }");
  EXPECT_NE(message.find("'run.dimension' = 4"), std::string::npos) << message;
  EXPECT_NE(message.find("2 <= value <= 3"), std::string::npos) << message;
}

TEST(CaseLoader, MissingRequiredFieldIsNamedWithItsSectionLine) {
  const std::string message = error_of("title: \"t\"\n\nrun { output_dir: \"x\" }\n");
  EXPECT_NE(message.find("bad.textproto:3:"), std::string::npos) << message;
  EXPECT_NE(message.find("required field 'run.end_time' is missing"), std::string::npos)
      << message;
}

TEST(CaseLoader, UnknownFieldListsTheAllowedOnes) {
  const std::string message = error_of("run {\n end_tme: 1\n}\n");
  EXPECT_NE(message.find("bad.textproto:2:"), std::string::npos) << message;
  EXPECT_NE(message.find("unknown field 'end_tme'"), std::string::npos) << message;
  EXPECT_NE(message.find("end_time, output_dir"), std::string::npos) << message;
}

TEST(CaseLoader, SyntaxErrorGivesLineAndColumn) {
  const std::string message = error_of("run { end_time: 1 }\nwaveform { period_s: }\n");
  EXPECT_NE(message.find("bad.textproto:2:"), std::string::npos) << message;
}

TEST(CaseLoader, NonFiniteNumbersAreRejected) {
  const std::string message = error_of("run { end_time: inf }");
  EXPECT_NE(message.find("'run.end_time' = inf"), std::string::npos) << message;
}

TEST(CaseLoader, MissingFileIsNamed) {
  try {
    valvefsi::load_case("/nonexistent/dir/case.textproto");
    FAIL() << "expected CaseError";
  } catch (const CaseError& error) {
    EXPECT_NE(std::string(error.what()).find("/nonexistent/dir/case.textproto"), std::string::npos);
    EXPECT_NE(std::string(error.what()).find("no such file"), std::string::npos);
  }
}

TEST(CaseLoader, LoadsFromFileAndResolvesRelativePaths) {
  const auto dir = std::filesystem::temp_directory_path() / "valvefsi_case_loader_test";
  std::filesystem::create_directories(dir);
  const auto file = dir / "c.textproto";
  std::ofstream(file) << "# a comment line\nrun { end_time: 0.25 output_dir: \"o\" }\n";
  const auto parsed = valvefsi::load_case(file);
  EXPECT_DOUBLE_EQ(parsed.run().end_time(), 0.25);
  EXPECT_EQ(valvefsi::resolve_case_path(file, "meshes/a.h5"), dir / "meshes/a.h5");
  EXPECT_EQ(valvefsi::resolve_case_path(file, "/abs/a.h5"), std::filesystem::path("/abs/a.h5"));
  std::filesystem::remove_all(dir);
}

}  // namespace
