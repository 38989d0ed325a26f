# Fails when the README, a lesson or SPEED.md names a file of the project (`engine/...`,
# `exercises/...`, `solutions/...`, `tests/...`, `lessons/...` in backquotes) that does not exist:
# the "Where it lives" tables must follow the files when they move. Run with -DROOT=<project>.
file(GLOB docs ${ROOT}/README.md ${ROOT}/lessons/*/README.md ${ROOT}/engine/fast/SPEED.md)
set(missing "")
set(seen 0)
foreach(doc ${docs})
  file(READ ${doc} text)
  string(REGEX MATCHALL "`(engine|exercises|solutions|tests|lessons)/[A-Za-z0-9_./-]+`" paths
         "${text}")
  foreach(quoted ${paths})
    string(REPLACE "`" "" path "${quoted}")
    math(EXPR seen "${seen} + 1")
    # A student release leaves out the solutions, the hidden grading tests and the mistakes
    # planted in copies of the solutions on purpose.
    set(left_out FALSE)
    foreach(withheld solutions tests/grade-hidden tests/grade/harness/planted)
      if(path MATCHES "^${withheld}(/|$)" AND NOT EXISTS ${ROOT}/${withheld})
        set(left_out TRUE)
      endif()
    endforeach()
    if(NOT EXISTS ${ROOT}/${path} AND NOT left_out)
      file(RELATIVE_PATH name ${ROOT} ${doc})
      string(APPEND missing "\n  ${name}: ${path}")
    endif()
  endforeach()
endforeach()
if(seen LESS 50)
  message(FATAL_ERROR "found only ${seen} paths in the docs: the check is looking in the wrong place")
endif()
if(missing)
  message(FATAL_ERROR "the docs name files that are not there:${missing}")
endif()
message(STATUS "${seen} paths named in the docs, every one there")
