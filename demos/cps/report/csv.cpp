#include "report/csv.h"

#include "output/atomic_file.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace cps::cli {

std::size_t CsvTable::column_index(std::string_view column) const {
  for (std::size_t c = 0; c < columns.size(); ++c) {
    if (columns[c] == column) return c;
  }
  return columns.size();
}

const std::string& CsvTable::cell(std::size_t row, std::string_view column) const {
  static const std::string empty;
  const std::size_t c = column_index(column);
  return c < columns.size() ? rows.at(row).at(c) : empty;
}

CsvTable read_csv(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + file.string());
  const std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  if (in.bad()) throw std::runtime_error("cannot read " + file.string());
  CsvTable table;
  // RFC 4180: a record ends at LF or CRLF outside quotes; a cell in double quotes may hold
  // commas, quotes (doubled) and line breaks.
  std::vector<std::string> record;
  std::string cell;
  bool quoted = false;        // inside a quoted cell
  bool any = false;           // the record has a character
  std::size_t line = 1;       // the physical line being read
  std::size_t first_line = 1; // where the record began
  const auto end_record = [&] {
    record.push_back(std::move(cell));
    cell.clear();
    if (table.columns.empty() && table.rows.empty() && first_line == 1) {
      table.columns = std::move(record);
    } else if (any) {
      record.resize(table.columns.size());  // missing cells "", extra ones dropped
      table.rows.push_back(std::move(record));
      table.lines.push_back(first_line);
    }
    record.clear();
    any = false;
    first_line = line;
  };
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (quoted) {
      if (c == '"' && i + 1 < text.size() && text[i + 1] == '"') {
        cell += '"';
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        if (c == '\n') ++line;
        cell += c;
      }
    } else if (c == '"' && cell.empty()) {
      quoted = true;
      any = true;
    } else if (c == ',') {
      record.push_back(std::move(cell));
      cell.clear();
      any = true;
    } else if (c == '\n' || (c == '\r' && i + 1 < text.size() && text[i + 1] == '\n')) {
      if (c == '\r') ++i;
      ++line;
      end_record();
    } else {
      cell += c;
      any = true;
    }
  }
  if (quoted) {
    throw std::runtime_error(file.string() + " line " + std::to_string(first_line) +
                             ": a quoted cell is not closed (a '\"' is missing)");
  }
  if (any || !cell.empty() || (table.columns.empty() && !text.empty())) end_record();
  return table;
}

std::vector<std::map<std::string, std::string>> csv_records(const CsvTable& table) {
  std::vector<std::map<std::string, std::string>> records;
  for (const std::vector<std::string>& row : table.rows) {
    std::map<std::string, std::string>& r = records.emplace_back();
    for (std::size_t c = 0; c < table.columns.size(); ++c) r[table.columns[c]] = row[c];
  }
  return records;
}

std::string csv_text(const CsvTable& table) {
  std::ostringstream out;
  // RFC 4180: a cell holding a comma, a quote or a line break in quotes, its quotes doubled.
  const auto line = [&out](const std::vector<std::string>& cells) {
    for (std::size_t c = 0; c < cells.size(); ++c) {
      if (c > 0) out << ',';
      const std::string& cell = cells[c];
      if (cell.find_first_of(",\"\r\n") == std::string::npos) {
        out << cell;
        continue;
      }
      out << '"';
      for (const char ch : cell) out << (ch == '"' ? "\"\"" : std::string(1, ch));
      out << '"';
    }
    out << "\n";
  };
  line(table.columns);
  for (const std::vector<std::string>& row : table.rows) line(row);
  return out.str();
}

void write_csv(const std::filesystem::path& file, const CsvTable& table) {
  write_text_atomic(file, csv_text(table));
}

std::string number(double v) {
  if (!std::isfinite(v)) return "";
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", v);
  return text;
}

double at_csv_precision(double v) { return parse_number(number(v)); }

double parse_number(const std::string& text) {
  if (text.empty()) return std::nan("");
  return std::strtod(text.c_str(), nullptr);
}

}  // namespace cps::cli
