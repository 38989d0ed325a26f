# What the `clothlab bench` command tests share (included by cli_bench_*.cmake).

# run_bench(WHAT ARGS...): runs `clothlab ARGS...` in WORK; stops the test with its output when it
# fails. Leaves its output in `out` and `err`.
macro(run_bench what)
  execute_process(COMMAND ${CLOTHLAB} ${ARGN}
                  WORKING_DIRECTORY ${WORK}
                  RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT code EQUAL 0)
    message(FATAL_ERROR "${what} failed with ${code}\n${out}${err}")
  endif()
endmacro()

# check_header(CSV EXPECTED): the CSV's first line is EXPECTED.
function(check_header csv expected)
  file(STRINGS ${csv} lines LIMIT_COUNT 1)
  if(NOT lines STREQUAL expected)
    message(FATAL_ERROR "${csv}'s header is\n  ${lines}\nexpected\n  ${expected}")
  endif()
endfunction()

# check_plot(SCRIPT SVG ERR): the plot script was written; the SVG was drawn, or, with no
# matplotlib (and CLOTHLAB_REQUIRE_PLOT unset), the command's errors ERR say how to get it.
function(check_plot script svg err)
  if(NOT EXISTS ${script})
    message(FATAL_ERROR "the plot script ${script} was not written next to the CSV")
  endif()
  if(EXISTS ${svg})
    file(READ ${svg} text)
    if(NOT text MATCHES "<svg")
      message(FATAL_ERROR "${svg} is not an SVG file")
    endif()
  elseif(DEFINED ENV{CLOTHLAB_REQUIRE_PLOT})
    message(FATAL_ERROR "no plot was drawn, and CLOTHLAB_REQUIRE_PLOT is set:\n${err}")
  elseif(NOT err MATCHES "python3-matplotlib")
    message(FATAL_ERROR "no plot was drawn and the warning does not say how to get one:\n${err}")
  endif()
endfunction()
