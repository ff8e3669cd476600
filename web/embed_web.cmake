# cmake -DOUTPUT=header.h -DFILES="index.html;conus-view.js" -P embed_web.cmake
# Writes one header with `inline constexpr const char kWeb<Name>[]` per file of the browser viewer,
# the file's text as a raw string literal; <Name> is the file name in PascalCase
# (conus-view.js -> ConusViewJs). `conus web` writes them and `conus serve` serves them, so the
# page needs no files installed beside the binary.
set(_text "// Generated from web/ by embed_web.cmake; do not edit.\n#pragma once\n\nnamespace conus::cli::web {\n")
foreach(_path IN LISTS FILES)
  get_filename_component(_file "${_path}" NAME)
  string(REGEX REPLACE "[._-]" ";" _parts "${_file}")
  set(_name "")
  foreach(_part IN LISTS _parts)
    string(SUBSTRING "${_part}" 0 1 _first)
    string(SUBSTRING "${_part}" 1 -1 _rest)
    string(TOUPPER "${_first}" _first)
    string(APPEND _name "${_first}${_rest}")
  endforeach()
  file(READ "${_path}" _source)
  if(_source MATCHES "\\)web\"")
    message(FATAL_ERROR "${_path} contains the raw string delimiter )web\"")
  endif()
  string(APPEND _text "\n// ${_file}\ninline constexpr const char kWeb${_name}[] = R\"web(${_source})web\";\n")
endforeach()
string(APPEND _text "\n}  // namespace conus::cli::web\n")
file(WRITE "${OUTPUT}" "${_text}")
