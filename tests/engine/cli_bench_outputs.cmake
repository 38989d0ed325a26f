# Where the bench commands write: never over a user's file by surprise, as `clothlab run` never
# writes into a user's folder without --force. A CSV, an --out folder or a --plot that the bench
# did not write is refused before anything is measured, naming it, and left as it was; the
# bench's own files from an earlier run are replaced; --force replaces anything.
include(${CMAKE_CURRENT_LIST_DIR}/cli_bench_checks.cmake)
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK}/user ${WORK}/target ${WORK}/empty)
file(WRITE ${WORK}/mine.csv "my precious data\n")
file(WRITE ${WORK}/user/accuracy.csv "mine\n")
file(WRITE ${WORK}/user/mine.svg "<svg>mine</svg>\n")
file(WRITE ${WORK}/target/keep.txt "mine\n")
file(CREATE_LINK target ${WORK}/link SYMBOLIC)
file(CREATE_LINK mine.csv ${WORK}/link.csv SYMBOLIC)

# refused(WHAT EXPECTED ARGS...): `clothlab ARGS...` exits 1 with EXPECTED in its errors, having
# measured nothing (its first line of figures never printed).
function(refused what expected)
  execute_process(COMMAND ${CLOTHLAB} ${ARGN}
                  WORKING_DIRECTORY ${WORK}
                  RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT code EQUAL 1)
    message(FATAL_ERROR "${what}: expected exit code 1, got ${code}\n${out}${err}")
  endif()
  string(FIND "${err}" "${expected}" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "${what}: expected '${expected}' in the errors:\n${err}")
  endif()
  if(NOT out STREQUAL "")
    message(FATAL_ERROR "${what}: refused after it had started measuring:\n${out}")
  endif()
endfunction()

# unchanged(FILE TEXT): FILE still holds TEXT.
function(unchanged file text)
  file(READ ${file} now)
  if(NOT now STREQUAL text)
    message(FATAL_ERROR "${file} was changed; it holds:\n${now}")
  endif()
endfunction()

set(speed bench speed --sizes 3 --repeats 1 --min-seconds 0.001 --variants reference
          --threads 1 --no-student)
refused("bench speed --csv onto a user's file"
        "mine.csv exists and is not a CSV file this bench wrote (its first line is not the \
bench's header); choose another --csv, or add --force to replace it"
        ${speed} --csv mine.csv)
unchanged(${WORK}/mine.csv "my precious data\n")
refused("bench speed --csv onto a symbolic link"
        "link.csv is a symbolic link; choose another --csv, or add --force" ${speed} --csv link.csv)
refused("bench roofline --csv onto a user's file" "mine.csv exists and is not a CSV file"
        bench roofline --quick --csv mine.csv)
unchanged(${WORK}/mine.csv "my precious data\n")
# The bench's own CSV, twice; a user's with --force.
run_bench("bench speed --csv a new file" ${speed} --csv speed.csv)
run_bench("bench speed --csv its own file" ${speed} --csv speed.csv)
check_header(${WORK}/speed.csv "variant,n,threads,springs,ns_per_spring_step,steps_per_s,particles")
run_bench("bench speed --csv onto a user's file with --force" ${speed} --csv mine.csv --force)
check_header(${WORK}/mine.csv "variant,n,threads,springs,ns_per_spring_step,steps_per_s,particles")

set(accuracy bench accuracy --quick --time 0.4 --min-seconds 0.001 --integrators symplectic-euler)
refused("bench accuracy --out a user's folder"
        "--out user is a folder this bench did not write (it holds no accuracy.csv of the \
bench's); choose another --out (a new or empty folder), or add --force"
        ${accuracy} --out user --no-plot)
unchanged(${WORK}/user/accuracy.csv "mine\n")
refused("bench accuracy --out a symbolic link" "--out link is a symbolic link; choose another --out"
        ${accuracy} --out link --no-plot)
file(GLOB target RELATIVE ${WORK}/target ${WORK}/target/*)
if(NOT target STREQUAL "keep.txt")
  message(FATAL_ERROR "bench accuracy wrote through the link: the target holds ${target}")
endif()
refused("bench accuracy --plot onto a user's file"
        "--plot user/mine.svg exists and is not a plot this bench drew (one lies beside the \
bench's accuracy.csv); choose another --plot, or add --force to replace it"
        ${accuracy} --out fresh --plot user/mine.svg)
unchanged(${WORK}/user/mine.svg "<svg>mine</svg>\n")
if(EXISTS ${WORK}/fresh)
  message(FATAL_ERROR "bench accuracy made its --out folder before it refused the --plot")
endif()
refused("bench methods --out a user's folder"
        "--out user is a folder this bench did not write (it holds no methods.csv of the bench's)"
        bench methods --quick --out user --no-plot)
# A new folder, an empty one, the bench's own folder again; a user's with --force.
run_bench("bench accuracy --out a new folder" ${accuracy} --out fresh --no-plot)
run_bench("bench accuracy --out its own folder" ${accuracy} --out fresh --no-plot)
run_bench("bench accuracy --out an empty folder" ${accuracy} --out empty --no-plot)
run_bench("bench accuracy --out a user's folder with --force" ${accuracy} --out user --no-plot
          --force)
check_header(${WORK}/user/accuracy.csv
             "problem,integrator,dt,steps,error,wall_s_per_sim_s,force_evals_per_sim_s,stable")
