# Helpers of the -P scripts that turn text files into C++ headers (renderers/cmake/embed_shaders.cmake,
# web/embed_web.cmake): each file becomes `inline constexpr const char k<Prefix><Name>[]`, its text as
# a raw string literal.

# <Name>: `stem` in PascalCase, its parts split at '.', '_' and '-' (encode.frag -> EncodeFrag).
function(conus_pascal_case out stem)
  string(REGEX REPLACE "[._-]" ";" _parts "${stem}")
  set(_name "")
  foreach(_part IN LISTS _parts)
    string(SUBSTRING "${_part}" 0 1 _first)
    string(SUBSTRING "${_part}" 1 -1 _rest)
    string(TOUPPER "${_first}" _first)
    string(APPEND _name "${_first}${_rest}")
  endforeach()
  set(${out} "${_name}" PARENT_SCOPE)
endfunction()

# Appends to `text` the constant k<prefix><name> holding `source` (from the file `file`, named in
# the comment above it) between R"<delimiter>( and )<delimiter>"; a source that holds the closing
# delimiter is an error naming `file`.
function(conus_append_embedded text prefix name file source delimiter)
  if(source MATCHES "\\)${delimiter}\"")
    message(FATAL_ERROR "${file} contains the raw string delimiter )${delimiter}\"")
  endif()
  get_filename_component(_file "${file}" NAME)
  set(${text} "${${text}}\n// ${_file}\ninline constexpr const char k${prefix}${name}[] = R\"${delimiter}(${source})${delimiter}\";\n" PARENT_SCOPE)
endfunction()
