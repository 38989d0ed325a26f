# The student build runs scenes on the student's kernels. On a shipped stub it stops with exit
# code 4 and names the exercise to do; once solved, it runs like the reference.
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
execute_process(COMMAND ${CLOTHLAB} WORKING_DIRECTORY ${WORK}
                RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(code EQUAL 0)
  return()  # the student has solved what the demo needs
endif()
if(NOT code EQUAL 4 OR NOT err MATCHES "exercise ex01\\.[0-9] is not implemented yet: see lessons/01-particles-and-euler/README.md")
  message(FATAL_ERROR "expected exit code 4 naming an ex01 exercise, got ${code}:\n${out}${err}")
endif()
