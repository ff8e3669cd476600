# cmake -DOUTPUT=header.h -DSHADERS="a.glsl;b.glsl" -P embed_shaders.cmake
# Writes one header with `inline constexpr const char kShader<Name>[]` per shader, the file's text
# as a raw string literal; <Name> is the file name in PascalCase (encode.frag.glsl -> EncodeFrag).
# A line `#include "x.inc.glsl"` is replaced by that file's text (from the same folder), so shared
# GLSL (Equation 1) is written once; *.inc.glsl files are only included, never embedded alone.
include("${CMAKE_CURRENT_LIST_DIR}/../../cmake/embed_text.cmake")
set(_text "// Generated from renderers/shaders/*.glsl by embed_shaders.cmake; do not edit.\n#pragma once\n\nnamespace conus::renderers::shaders {\n")
foreach(_path IN LISTS SHADERS)
  get_filename_component(_file "${_path}" NAME)
  if(_file MATCHES "\\.inc\\.glsl$")
    continue()
  endif()
  get_filename_component(_folder "${_path}" DIRECTORY)
  string(REGEX REPLACE "\\.glsl$" "" _stem "${_file}")
  conus_pascal_case(_name "${_stem}")
  file(READ "${_path}" _source)
  string(REGEX MATCHALL "#include \"[^\"]+\"" _includes "${_source}")
  foreach(_include IN LISTS _includes)
    string(REGEX REPLACE "#include \"([^\"]+)\"" "\\1" _inc_file "${_include}")
    if(NOT EXISTS "${_folder}/${_inc_file}")
      message(FATAL_ERROR "${_path}: ${_include}: no such file in ${_folder}")
    endif()
    file(READ "${_folder}/${_inc_file}" _included)
    string(REPLACE "${_include}" "${_included}" _source "${_source}")
  endforeach()
  conus_append_embedded(_text Shader "${_name}" "${_path}" "${_source}" glsl)
endforeach()
string(APPEND _text "\n}  // namespace conus::renderers::shaders\n")
file(WRITE "${OUTPUT}" "${_text}")
