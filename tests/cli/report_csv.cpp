#include "report_csv.h"

#include "report/csv.h"

namespace cli_test {

CsvRows read_report_csv(const std::filesystem::path& file) {
  const cps::cli::CsvTable table = cps::cli::read_csv(file);
  return {table.columns, cps::cli::csv_records(table)};
}

}  // namespace cli_test
