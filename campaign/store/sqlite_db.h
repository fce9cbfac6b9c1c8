#pragma once
/// @file
/// @brief A thin RAII layer over the SQLite C API (connection, prepared statement, transaction).

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

struct sqlite3;
struct sqlite3_stmt;

namespace capsim::campaign {

/// @brief A SQLite error (message includes the file and SQLite's own text).
class DbError : public std::runtime_error {
 public:
  DbError(const std::string& msg, int code) : std::runtime_error(msg), code_(code) {}
  /// @brief SQLite primary result code.
  int code() const { return code_; }

 private:
  int code_;
};

/// @brief A bindable / readable SQL value.
using SqlValue = std::variant<std::nullptr_t, std::int64_t, double, std::string>;

class Db;

/// @brief Rows of a query with named columns (what `capsim query` renders).
struct Table {
  std::vector<std::string> columns;             ///< column names (JSON keys)
  std::vector<std::vector<SqlValue>> rows;      ///< one vector per row, same length as columns
  /// @brief Columns whose text is a JSON document: JSON output nests it (Markdown and CSV print the text).
  std::vector<std::string> json_columns;
};

/// @brief A prepared statement; bind with bind(i, v) (1-based), step() until it returns false.
class Stmt {
 public:
  Stmt(Db& db, const std::string& sql);
  ~Stmt();
  Stmt(const Stmt&) = delete;
  Stmt& operator=(const Stmt&) = delete;

  /// @brief Binds parameter @p i (1-based).
  Stmt& bind(int i, const SqlValue& v);
  /// @brief Binds an optional double (nullopt -> NULL).
  Stmt& bind_opt(int i, std::optional<double> v) { return bind(i, v ? SqlValue{*v} : SqlValue{nullptr}); }
  /// @brief Steps; true while a row is available.
  bool step();
  /// @brief Resets for re-execution (bindings kept).
  void reset();
  /// @brief Number of result columns.
  int columns() const;
  /// @brief Name of result column @p c.
  std::string column_name(int c) const;
  /// @brief Value of column @p c of the current row.
  SqlValue column(int c) const;
  /// @brief Text of column @p c (empty for NULL).
  std::string text(int c) const;
  /// @brief Integer of column @p c (0 for NULL).
  std::int64_t integer(int c) const;
  /// @brief Double of column @p c, nullopt for NULL.
  std::optional<double> real(int c) const;
  /// @brief Whether column @p c is NULL.
  bool is_null(int c) const;
  /// @brief True if the statement does not write (sqlite3_stmt_readonly).
  bool readonly() const;

 private:
  Db& db_;
  sqlite3_stmt* stmt_ = nullptr;
};

/// @brief A connection.
class Db {
 public:
  /// @brief Opens @p path; @p readonly opens with SQLITE_OPEN_READONLY, otherwise read-write (+create if
  /// @p create). Sets a busy timeout. @throws DbError.
  Db(const std::string& path, bool readonly, bool create);
  ~Db();
  Db(const Db&) = delete;
  Db& operator=(const Db&) = delete;

  /// @brief Runs one or more statements without results. @throws DbError.
  void exec(const std::string& sql);
  /// @brief Runs a single-value query; nullopt if no row.
  std::optional<SqlValue> scalar(const std::string& sql);
  /// @brief Rows changed by the last statement.
  int changes() const;
  /// @brief Raw handle.
  sqlite3* handle() { return db_; }
  /// @brief The file path.
  const std::string& path() const { return path_; }
  /// @brief Throws DbError with the last SQLite message if @p rc is an error.
  void check(int rc, const std::string& what) const;

 private:
  sqlite3* db_ = nullptr;
  std::string path_;
};

/// @brief BEGIN IMMEDIATE ... COMMIT; rolls back if destroyed without commit().
class Transaction {
 public:
  explicit Transaction(Db& db);
  ~Transaction();
  /// @brief Commits.
  void commit();

 private:
  Db& db_;
  bool done_ = false;
};

}  // namespace capsim::campaign
