# Two scenes of one file name in two folders (lessons 12 and 13 both ship hanging-mass.toml) run
# into two default output folders, clothlab-out/<folder>/<scene>/: one never replaces the other.
file(REMOVE_RECURSE ${WORK})
foreach(lesson 12-xpbd 13-local-global)
  file(WRITE ${WORK}/${lesson}/hanging-mass.toml "title = \"${lesson}\"
[[particle]]
position = [0, 0, 0]
mass = 1
[gravity]
[integrator]
dt = 0.01
duration = 0.1
")
endforeach()
foreach(lesson 12-xpbd 13-local-global)
  execute_process(COMMAND ${CLOTHLAB} run ${lesson}/hanging-mass.toml WORKING_DIRECTORY ${WORK}
                  RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT code EQUAL 0 OR NOT out MATCHES "wrote [0-9]+ frames to clothlab-out/${lesson}/hanging-mass/")
    message(FATAL_ERROR "the run of ${lesson}/hanging-mass.toml (exit ${code}):\n${out}${err}")
  endif()
endforeach()
# Run from inside the scene's folder, the same folder.
execute_process(COMMAND ${CLOTHLAB} run hanging-mass.toml WORKING_DIRECTORY ${WORK}/12-xpbd
                RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT code EQUAL 0 OR NOT out MATCHES "wrote [0-9]+ frames to clothlab-out/12-xpbd/hanging-mass/")
  message(FATAL_ERROR "the run from the scene's folder (exit ${code}):\n${out}${err}")
endif()
foreach(lesson 12-xpbd 13-local-global)
  file(READ ${WORK}/clothlab-out/${lesson}/hanging-mass/view.html page)
  if(NOT page MATCHES "\"title\":\"${lesson}\"")
    message(FATAL_ERROR "clothlab-out/${lesson}/hanging-mass/view.html is not ${lesson}'s run")
  endif()
endforeach()
