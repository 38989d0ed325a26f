# bench_csv.cmake: the CSV contract the bench commands' test scripts share (include() it).
#
# bench_csv_rows(FILE HEADER FIRST OUT [SIGNED...]): FILE's first line is HEADER; every other row
# has as many fields as HEADER, and its fields FIRST and after (counted from 0) are positive finite
# numbers, except those whose indices follow OUT, which are finite numbers of either sign (a
# difference of two measurements). OUT receives the rows, each a line of comma-separated fields.
function(bench_csv_rows file header first out)
  set(signed ${ARGN})
  file(STRINGS ${file} lines)
  list(GET lines 0 found)
  if(NOT found STREQUAL header)
    message(FATAL_ERROR "${file}: the header is\n  ${found}\nexpected\n  ${header}")
  endif()
  list(REMOVE_AT lines 0)
  string(REPLACE "," ";" names "${header}")
  list(LENGTH names expected)
  math(EXPR last "${expected} - 1")
  foreach(line ${lines})
    string(REPLACE "," ";" fields "${line}")
    list(LENGTH fields count)
    if(NOT count EQUAL expected)
      message(FATAL_ERROR "row '${line}' has ${count} fields; expected ${expected}")
    endif()
    foreach(index RANGE ${first} ${last})
      list(GET fields ${index} value)
      list(FIND signed ${index} at)
      if(NOT at EQUAL -1)
        if(NOT value MATCHES "^-?[0-9]+(\\.[0-9]+)?(e[-+][0-9]+)?$")
          message(FATAL_ERROR "row '${line}': field ${index} is '${value}'; expected a finite "
                              "number")
        endif()
        continue()
      endif()
      # A positive finite number: digits, maybe a fraction and an exponent; no nan, inf or sign.
      if(NOT value MATCHES "^[0-9]+(\\.[0-9]+)?(e[-+][0-9]+)?$" OR value MATCHES "^0(\\.0+)?$")
        message(FATAL_ERROR "row '${line}': field ${index} is '${value}'; expected a positive "
                            "finite number")
      endif()
    endforeach()
  endforeach()
  set(${out} "${lines}" PARENT_SCOPE)
endfunction()
