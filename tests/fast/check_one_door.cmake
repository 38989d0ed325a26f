# Fails when a file of the lecture's engine (ENGINE/clothlab/, every folder under it) includes
# anything from the engine room (ENGINE/fast/): the physics knows the fast engine only through
# clothlab/core/backend.hpp. Names each offending file and line.
file(GLOB_RECURSE physics ${ENGINE}/clothlab/*.hpp ${ENGINE}/clothlab/*.cpp ${ENGINE}/clothlab/*.in)
list(LENGTH physics count)
if(count LESS 20)
  message(FATAL_ERROR "found only ${count} files under ${ENGINE}/clothlab: the check is looking "
                      "in the wrong place")
endif()
set(breaches "")
foreach(path ${physics})
  file(STRINGS ${path} lines REGEX "^[ \t]*#[ \t]*include[ \t]*[<\"]fast/")
  foreach(line ${lines})
    file(RELATIVE_PATH name ${ENGINE} ${path})
    string(APPEND breaches "\n  ${name}: ${line}")
  endforeach()
endforeach()
if(breaches)
  message(FATAL_ERROR "the lecture's engine includes the engine room (engine/fast/); reach it "
                      "through World::backend instead:${breaches}")
endif()
message(STATUS "${count} files of engine/clothlab/ checked: none includes engine/fast/")
