// include_filter.hpp: what an exercise file may have the compiler read, checked before it is
// compiled.
//
// A submission's exercise file may include the standard library's and the engine's headers and
// nothing else: not a solution, not a grading test, not /etc/passwd. The check reads the file as
// the preprocessor does (translation phases 1 to 3 of C++20, as GCC implements them): a byte-order
// mark is skipped; CR LF, LF and a lone CR each end a line; a backslash ends a line's splice even
// with spaces, tabs, form feeds or vertical tabs before the line's end; comments are one space (a
// comment that spans lines leaves the directive it is in one line); raw string literals hold what
// they hold. Then every directive and operator that names a file is looked at.
#pragma once

#include <string>

namespace clothlab::app {

// Why the exercise file `text` (exercises/`name`) may not be compiled, as
// "exercises/NAME:LINE: error: what, and what is allowed", or "" when it may. Refused:
//  - #include of anything but <...> or "clothlab/..." by a name without ".." or a leading "/"
//    or a backslash, and #include of a name a macro gives (#define H <...> then #include H);
//  - #include_next, #import, #embed, import declarations, #line and line markers (# 1 "file",
//    which make the compiler's messages quote another file);
//  - __has_include (and __has_include_next, __has_embed) but of a header an #include may name,
//    written out;
//  - _Pragma but of a string written out, and the pragmas that name a file (GCC dependency,
//    GCC pch_preprocess), in either spelling;
//  - the token-pasting operator ##, which may build any of the names above from pieces;
//  - the assembler's .incbin, which reads any file into the program.
std::string include_problem(const std::string& name, const std::string& text);

}  // namespace clothlab::app
