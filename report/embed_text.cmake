# Writes OUTPUT, a C++ header holding the files JS and CSS as string constants
# (kDygraphJs, kDygraphCss), so the HTML report can inline them and open offline.
function(as_literal path variable)
  file(READ "${path}" hex HEX)
  string(REGEX REPLACE "([0-9a-f][0-9a-f])" "'\\\\x\\1'," bytes "${hex}")
  set(${variable} "${bytes}" PARENT_SCOPE)
endfunction()
as_literal("${JS}" js)
as_literal("${CSS}" css)
file(WRITE "${OUTPUT}" "// Generated from ${JS} and ${CSS} (libjs-dygraphs); do not edit.\n#pragma once\nnamespace impactlab {\ninline constexpr char kDygraphJsBytes[] = {${js} 0};\ninline constexpr const char* kDygraphJs = kDygraphJsBytes;\ninline constexpr char kDygraphCssBytes[] = {${css} 0};\ninline constexpr const char* kDygraphCss = kDygraphCssBytes;\n}\n")
