#pragma once
// The report's CSV files read back by the report library's own reader (demos/cps/report/csv.h),
// for the command-line tests. In a file of its own so that test files with a local function
// called cps need not include the library's headers. Link cps_report and tests/cli/report_csv.cpp.

#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace cli_test {

/// A CSV file of `cps report`: its header (column names, in order) and its rows, each as column
/// name -> cell ("" where empty).
struct CsvRows {
  std::vector<std::string> columns;
  std::vector<std::map<std::string, std::string>> rows;
};

/// Reads `file` with cps::cli::read_csv. Throws std::runtime_error if it cannot be opened.
CsvRows read_report_csv(const std::filesystem::path& file);

}  // namespace cli_test
