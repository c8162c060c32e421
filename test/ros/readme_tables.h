// The README's tables, read as documentation: for the section under a heading, each table's
// rows, and in each row the names written in backticks in its first cell. Tests hold the code's
// key tables against them, so that a documented key the code refuses fails a test.
#pragma once

#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

namespace collision_response::testing {

using Row = std::vector<std::string>;  // the backticked names of a row's first cell
using Table = std::vector<Row>;

/// The tables of the README section that starts with the line `heading` ("### Parameters"),
/// up to the next heading of the same level or higher. Empty when there is no such section.
inline std::vector<Table> readmeTables(const std::string& heading) {
  std::ifstream file(COLLISION_RESPONSE_README);
  std::vector<Table> tables;
  std::string line;
  bool inside = false;
  bool in_table = false;
  const std::size_t level = heading.find(' ');
  while (std::getline(file, line)) {
    if (line == heading) {
      inside = true;
      continue;
    }
    if (!inside) continue;
    const std::size_t hashes = line.find_first_not_of('#');
    if (hashes > 0 && hashes != std::string::npos && hashes <= level && line[hashes] == ' ') break;
    if (line.rfind("|", 0) != 0) {
      in_table = false;
      continue;
    }
    if (!in_table) {  // the header row, then the |---| row
      tables.emplace_back();
      in_table = true;
      std::getline(file, line);
      continue;
    }
    const std::string first = line.substr(1, line.find('|', 1) - 1);
    Row names;
    static const std::regex kBackticked("`([^`]+)`");
    for (std::sregex_iterator it(first.begin(), first.end(), kBackticked), end; it != end; ++it) {
      names.push_back((*it)[1]);
    }
    tables.back().push_back(names);
  }
  return tables;
}

}  // namespace collision_response::testing
