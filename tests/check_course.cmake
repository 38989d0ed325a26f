# `clothlab course --check` names what disagrees with a manifest, and a broken manifest by file,
# line and column. Run with -DCLOTHLAB=<clothlab> -DROOT=<project> -DWORK=<scratch folder>.
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
file(READ ${ROOT}/course.toml manifest)

# check(NAME TEXT EXIT EXPECTED...): writes TEXT as a manifest, runs the check on it, and wants
# exit code EXIT and every EXPECTED piece in what it prints.
function(check name text exit_code)
  file(WRITE ${WORK}/${name}.toml "${text}")
  execute_process(COMMAND ${CLOTHLAB} course --check --manifest ${WORK}/${name}.toml
                  RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT code EQUAL exit_code)
    message(FATAL_ERROR "${name}: exit ${code}, expected ${exit_code}:\n${out}${err}")
  endif()
  foreach(piece ${ARGN})
    string(FIND "${out}${err}" "${piece}" at)
    if(at EQUAL -1)
      message(FATAL_ERROR "${name}: expected \"${piece}\" in:\n${out}${err}")
    endif()
  endforeach()
endfunction()

check(same "${manifest}" 0 "every lesson, exercise, header and file agrees with course.toml")

string(REPLACE "title = \"the spring-damper force\", points = 6"
               "title = \"the spring-damper force\", points = 7" points "${manifest}")
check(points "${points}" 1
      "lessons/02-spring-dampers/README.md has the exercise headings"
      "ex02.1: the spring-damper force (7 points)")

string(REPLACE "kernels = [\"spring_energy\"]" "kernels = [\"spring_energies\"]" kernel
               "${manifest}")
check(kernel "${kernel}" 1 "does not declare ex02.2's kernel spring_energies")

# Lesson 08's whole table, from its [[lesson]] to lesson 09's.
string(FIND "${manifest}" "[[lesson]]\nnumber = 8\n" eight_start)
string(FIND "${manifest}" "[[lesson]]\nnumber = 9\n" nine_start)
string(SUBSTRING "${manifest}" 0 ${eight_start} before_eight)
string(SUBSTRING "${manifest}" ${nine_start} -1 from_nine)
set(no_eight "${before_eight}${from_nine}")
check(no_eight "${no_eight}" 1 "lessons/08-stability is not in course.toml")

string(REPLACE "exercise_file = \"exercises/03_aerodynamics.cpp\""
               "exercise_file = \"exercises/03_aerodynamic.cpp\"" file_name "${manifest}")
check(file_name "${file_name}" 1 "the exercise file exercises/03_aerodynamic.cpp is missing"
      "exercises/03_aerodynamics.cpp is not in course.toml")

string(REPLACE "id = \"ex05.1\"" "id = \"ex06.1\"" wrong_id "${manifest}")
check(wrong_id "${wrong_id}" 2 "wrong_id.toml:" ": error: exercise id 'ex06.1'; expected ex05.K")

string(REPLACE "number = 4\ntitle = \"bending springs\"" "number = 4\ntitle = bending springs"
               syntax "${manifest}")
check(syntax "${syntax}" 2 "syntax.toml:" ": error:")
