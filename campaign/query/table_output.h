#pragma once
/// @file
/// @brief Result tables printed as Markdown, CSV or JSON (the --format of `capsim query`).

#include <string>
#include <vector>

#include "campaign/store/sqlite_db.h"

namespace capsim::campaign {

/// @brief A table of SQL values with named columns.
struct Table {
  std::vector<std::string> columns;             ///< column names (JSON keys)
  std::vector<std::vector<SqlValue>> rows;      ///< one vector per row, same length as columns
};

/// @brief Output formats.
enum class Format { kMarkdown, kCsv, kJson };

/// @brief Parses "md" | "markdown" | "csv" | "json". @throws BadInput.
Format parse_format(const std::string& s);

/// @brief Runs a read-only statement and collects its rows.
Table query_table(Db& db, Stmt& stmt);

/// @brief Renders a table: Markdown pipe table, RFC 4180 CSV with a header, or a JSON array of objects
/// (NULL -> null, numbers stay numbers).
std::string render(const Table& t, Format f);

/// @brief Text of one value for Markdown/CSV (NULL -> "", doubles in shortest round-trip form).
std::string cell_text(const SqlValue& v);

}  // namespace capsim::campaign
