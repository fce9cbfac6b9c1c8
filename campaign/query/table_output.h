#pragma once
/// @file
/// @brief Result tables printed as Markdown, CSV or JSON (the --format of `capsim query`).

#include <string>
#include <vector>

#include "campaign/store/sqlite_db.h"  // Table, SqlValue

namespace capsim::campaign {

/// @brief Output formats.
enum class Format { kMarkdown, kCsv, kJson };

/// @brief Parses "md" | "markdown" | "csv" | "json". @throws BadInput.
Format parse_format(const std::string& s);

/// @brief Renders a table: Markdown pipe table, RFC 4180 CSV with a header, or a JSON array of objects
/// (NULL -> null, numbers stay numbers).
std::string render(const Table& t, Format f);

/// @brief Text of one value for Markdown/CSV (NULL -> "", doubles in shortest round-trip form).
std::string cell_text(const SqlValue& v);

}  // namespace capsim::campaign
