# When the system will not start the threads a scene asks for, the run stops with an error that
# says so (it once aborted): here a process limit of 1 for the user that runs it. Root is not
# held to that limit, so as root the run is made as the user nobody.
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
file(WRITE ${WORK}/threads.toml "[cloth]
rows = 40
cols = 40
spacing = 0.01
mass = 0.1
pins = \"top-corners\"
[springs]
ks = 50
[gravity]
[integrator]
dt = 0.0005
duration = 0.01
[engine]
threads = 4
")
file(CHMOD ${WORK} ${WORK}/threads.toml PERMISSIONS OWNER_READ OWNER_WRITE OWNER_EXECUTE
     GROUP_READ GROUP_WRITE GROUP_EXECUTE WORLD_READ WORLD_WRITE WORLD_EXECUTE)
execute_process(COMMAND id -u OUTPUT_VARIABLE uid OUTPUT_STRIP_TRAILING_WHITESPACE)
set(as_user)
if(uid STREQUAL "0")
  set(as_user setpriv --reuid=65534 --regid=65534 --clear-groups)
endif()
execute_process(COMMAND ${as_user} prlimit --nproc=1:1 -- ${CLOTHLAB} run ${WORK}/threads.toml
                        --out ${WORK}/out
                RESULT_VARIABLE code ERROR_VARIABLE err OUTPUT_VARIABLE out)
if(code EQUAL 0)
  message(FATAL_ERROR "the run succeeded: no thread limit to test here\n${out}${err}")
endif()
if(NOT err MATCHES "could not start thread 2 of the 4 asked for \\(.*\\); ask for fewer with \\[engine\\] threads or --threads")
  message(FATAL_ERROR "unexpected message (exit code ${code}):\n${out}${err}")
endif()
