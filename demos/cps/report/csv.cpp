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
  std::ifstream in(file);
  if (!in) throw std::runtime_error("cannot read " + file.string());
  CsvTable table;
  std::string line;
  std::getline(in, line);
  std::stringstream header(line);
  for (std::string c; std::getline(header, c, ',');) table.columns.push_back(c);
  for (std::size_t number = 2; std::getline(in, line); ++number) {
    if (line.empty()) continue;
    std::stringstream cells(line);
    table.lines.push_back(number);
    std::vector<std::string>& row = table.rows.emplace_back();
    for (std::size_t c = 0; c < table.columns.size(); ++c) {
      std::string cell;
      if (!std::getline(cells, cell, ',')) cell.clear();
      row.push_back(cell);
    }
  }
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
  const auto line = [&out](const std::vector<std::string>& cells) {
    for (std::size_t c = 0; c < cells.size(); ++c) out << (c ? "," : "") << cells[c];
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
