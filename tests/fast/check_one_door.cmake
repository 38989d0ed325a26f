# Fails when a file of the lecture's engine (ENGINE/clothlab/, every folder under it) includes
# anything from outside it: the engine room (ENGINE/fast/, which the physics knows only through
# clothlab/core/backend.hpp), or the rooms built on the physics (scene/, io/, app/, web/,
# analysis/). The physics wing imports nothing but itself and the libraries. Inside it, the
# integrators' factory (clothlab/integrators/methods.hpp, which includes every method) is included
# by its own source alone: the world and the methods know the interface, core/integrator.hpp.
# Names each offending file and line.
file(GLOB_RECURSE physics ${ENGINE}/clothlab/*.hpp ${ENGINE}/clothlab/*.cpp ${ENGINE}/clothlab/*.in)
list(LENGTH physics count)
if(count LESS 20)
  message(FATAL_ERROR "found only ${count} files under ${ENGINE}/clothlab: the check is looking "
                      "in the wrong place")
endif()
set(breaches "")
set(factory_breaches "")
foreach(path ${physics})
  file(STRINGS ${path} lines REGEX "^[ \t]*#[ \t]*include[ \t]*[<\"]")
  file(READ ${path} text)
  file(RELATIVE_PATH name ${ENGINE} ${path})
  foreach(line ${lines})
    set(outside FALSE)
    set(factory FALSE)
    if(line MATCHES "^[ \t]*#[ \t]*include[ \t]*[<\"](fast|scene|io|app|web|analysis)/")
      set(outside TRUE)
    elseif(line MATCHES "^[ \t]*#[ \t]*include[ \t]*[<\"]clothlab/integrators/methods\\.hpp"
           AND NOT name STREQUAL "clothlab/integrators/methods.cpp")
      set(factory TRUE)
    endif()
    if(outside OR factory)
      # The line's number, for the message: one more than the line ends before it.
      string(FIND "${text}" "${line}" at)
      string(SUBSTRING "${text}" 0 ${at} before)
      string(REGEX MATCHALL "\n" ends "${before}")
      list(LENGTH ends number)
      math(EXPR number "${number} + 1")
      if(outside)
        string(APPEND breaches "\n  engine/${name}:${number}: ${line}")
      else()
        string(APPEND factory_breaches "\n  engine/${name}:${number}: ${line}")
      endif()
    endif()
  endforeach()
endforeach()
if(factory_breaches)
  message(FATAL_ERROR "the integrators' factory (clothlab/integrators/methods.hpp) is included "
                      "inside the lecture's engine; the world and the methods include the "
                      "interface, clothlab/core/integrator.hpp:${factory_breaches}")
endif()
if(breaches)
  message(FATAL_ERROR "the lecture's engine (engine/clothlab/) includes from outside it; the "
                      "engine room is reached through World::backend, and the rooms above the "
                      "physics (scene/, io/, app/, web/, analysis/) include the physics, never the "
                      "other way:${breaches}")
endif()
message(STATUS "${count} files of engine/clothlab/ checked: none includes from fast/, scene/, "
               "io/, app/, web/ or analysis/, and only its own source the integrators' factory")
