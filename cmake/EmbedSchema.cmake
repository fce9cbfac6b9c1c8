# Concatenates schemas/*.sql into C++ raw strings so the binary carries its DDL: capsim::kSchemaSql (every file,
# in order: a fresh database) and capsim::kSchemaParts (each file with the version its NNN_ prefix names: a
# database of version v is migrated by applying the parts above v, each once).
file(GLOB files "${DIR}/*.sql")
list(SORT files)
set(sql "")
set(parts "")
foreach(f IN LISTS files)
  file(READ "${f}" part)
  string(APPEND sql "${part}\n")
  get_filename_component(name "${f}" NAME)
  string(REGEX MATCH "^[0-9]+" num "${name}")
  if(num STREQUAL "")
    message(FATAL_ERROR "${f}: a schema file is named NNN_*.sql (NNN: the schema version it creates)")
  endif()
  math(EXPR num "${num}")
  string(APPEND parts "    {${num}, R\"capsimsql(${part})capsimsql\"},\n")
endforeach()
file(WRITE "${OUT}" "#pragma once\n// Generated from schemas/*.sql by cmake/EmbedSchema.cmake.\nnamespace capsim {\n"
     "inline constexpr const char* kSchemaSql = R\"capsimsql(${sql})capsimsql\";\n"
     "/// One schemas/NNN_*.sql file: the schema version it brings a database to, and its DDL.\n"
     "struct SchemaPart {\n  int version;\n  const char* sql;\n};\n"
     "inline constexpr SchemaPart kSchemaParts[] = {\n${parts}};\n}\n")
