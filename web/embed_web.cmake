# cmake -DOUTPUT=header.h -DFILES="index.html;conus-view.js" -P embed_web.cmake
# Writes one header with `inline constexpr const char kWeb<Name>[]` per file of the browser viewer,
# the file's text as a raw string literal; <Name> is the file name in PascalCase
# (conus-view.js -> ConusViewJs). `conus web` writes them and `conus serve` serves them, so the
# page needs no files installed beside the binary.
include("${CMAKE_CURRENT_LIST_DIR}/../cmake/embed_text.cmake")
set(_text "// Generated from web/ by embed_web.cmake; do not edit.\n#pragma once\n\nnamespace conus::cli::web {\n")
foreach(_path IN LISTS FILES)
  get_filename_component(_file "${_path}" NAME)
  conus_pascal_case(_name "${_file}")
  file(READ "${_path}" _source)
  conus_append_embedded(_text Web "${_name}" "${_path}" "${_source}" web)
endforeach()
string(APPEND _text "\n}  // namespace conus::cli::web\n")
file(WRITE "${OUTPUT}" "${_text}")
