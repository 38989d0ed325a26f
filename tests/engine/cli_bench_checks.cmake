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

# read_methods_csv(CSV ROWS WITH_LOCAL_GLOBAL): checks the header of a `bench methods` CSV and
# leaves its rows in `lines`, and in `rows_per_scene` the rows each scene has: ROWS, or
# WITH_LOCAL_GLOBAL when the engine has the local/global solver (the command's output `out` names
# it).
macro(read_methods_csv csv rows with_local_global)
  check_header(${csv} "scene,method,dt,substeps,iterations,steps,error,\
worst_strain,energy_lost,wall_s_per_sim_s,stable")
  file(STRINGS ${csv} lines)
  list(POP_FRONT lines)
  set(rows_per_scene ${rows})
  if(out MATCHES "local-global")
    set(rows_per_scene ${with_local_global})
  endif()
endmacro()

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
