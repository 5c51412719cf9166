#pragma once
// The report's CSV files, written and read by one piece of code, as RFC 4180 has them: a header
// record of column names, then one record per row, cells separated by commas; a cell holding a
// comma, a double quote or a line break (a scene file's path may) is written in double quotes
// with its quotes doubled. Records end at LF when written; LF or CRLF when read.

#include <cstddef>
#include <filesystem>
#include <map>
#include <string>
#include <string_view>
#include <vector>

namespace cps::cli {

/// A CSV file in memory: `columns` (the header, k names) and `rows` (n rows of k cells each, ""
/// where a cell is empty).
struct CsvTable {
  std::vector<std::string> columns;
  std::vector<std::vector<std::string>> rows;
  /// The line of its file (1-based; the header is line 1) of each row, as read_csv reads them;
  /// empty for a table made in memory.
  std::vector<std::size_t> lines;

  /// The index of `column` in `columns`, or columns.size() if the table has no such column.
  std::size_t column_index(std::string_view column) const;
  /// The cell of row `row` (< rows.size()) in `column`; "" if the table has no such column.
  const std::string& cell(std::size_t row, std::string_view column) const;
};

/// Reads `file` (RFC 4180: quoted cells, LF or CRLF): its first record is the header, each
/// further non-empty record a row (missing cells at its end are ""; cells past the header's count
/// dropped), with the line it begins on in `lines`. Throws std::runtime_error "cannot read FILE"
/// if it cannot be read, and naming the file and line for a quoted cell that is never closed.
CsvTable read_csv(const std::filesystem::path& file);

/// The rows of a table as maps, column name -> cell ("" where empty): every column in every row.
std::vector<std::map<std::string, std::string>> csv_records(const CsvTable& table);

/// The text of a table: the header line, then one line per row, each ended by "\n".
std::string csv_text(const CsvTable& table);

/// Writes csv_text(table) to `file` atomically (atomic_file.h). Throws std::runtime_error
/// "cannot write FILE: REASON" on failure.
void write_csv(const std::filesystem::path& file, const CsvTable& table);

/// A number as the report's CSVs and tables write it: 6 significant digits (printf "%.6g"), ""
/// for a value that is not finite.
std::string number(double v);

/// `v` as it reads back from its CSV text (number(v)): rounded to 6 significant digits; NaN
/// for a value that is not finite. Results keep their measures at this precision, so that a
/// report made from a sweep and one made from its CSVs (--merge) are the same.
double at_csv_precision(double v);

/// A cell's number: NaN where the text is empty or not a number (std::strtod of its start).
double parse_number(const std::string& text);

}  // namespace cps::cli
