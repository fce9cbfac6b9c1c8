# Concatenates schemas/*.sql into a C++ raw string (capsim::kSchemaSql) so the binary carries its DDL.
file(GLOB files "${DIR}/*.sql")
list(SORT files)
set(sql "")
foreach(f IN LISTS files)
  file(READ "${f}" part)
  string(APPEND sql "${part}\n")
endforeach()
file(WRITE "${OUT}" "#pragma once\n// Generated from schemas/*.sql by cmake/EmbedSchema.cmake.\nnamespace capsim {\ninline constexpr const char* kSchemaSql = R\"capsimsql(${sql})capsimsql\";\n}\n")
