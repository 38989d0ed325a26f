# `clothlab` with no command runs the demo and says where it wrote its frames.
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
execute_process(COMMAND ${CLOTHLAB} WORKING_DIRECTORY ${WORK}
                RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT code EQUAL 0)
  message(FATAL_ERROR "the demo failed with ${code}\n${out}${err}")
endif()
if(NOT out MATCHES "wrote [0-9]+ frames to clothlab-out/demo/")
  message(FATAL_ERROR "the demo did not say where its output is:\n${out}")
endif()
if(NOT EXISTS ${WORK}/clothlab-out/demo/energy.csv OR NOT EXISTS ${WORK}/clothlab-out/demo/positions.csv)
  message(FATAL_ERROR "the demo's files are missing")
endif()
