# `cmake --build build --target bakeoff-update-lesson`: copies what the `bakeoff` target measured
# (build/lessons/bakeoff/ and bakeoff-large/) into lessons/12-xpbd/, the CSVs and the plots the
# lesson shows. Nothing is copied unless every file is there, so the lesson's plots never come
# from two different runs.
#   cmake -DFROM=<build>/lessons -DTO=<source>/lessons/12-xpbd -P bakeoff_update_lesson.cmake
cmake_policy(VERSION 3.22)
set(pairs
    bakeoff/methods.csv bakeoff.csv
    bakeoff/speed.csv bakeoff-speed.csv
    bakeoff/methods.svg bakeoff.svg
    bakeoff-large/methods.csv bakeoff-large.csv
    bakeoff-large/methods.svg bakeoff-large.svg)
set(missing "")
set(sources "")
set(targets "")
while(pairs)
  list(POP_FRONT pairs from to)
  if(NOT EXISTS ${FROM}/${from})
    list(APPEND missing ${FROM}/${from})
  endif()
  list(APPEND sources ${FROM}/${from})
  list(APPEND targets ${TO}/${to})
endwhile()
if(missing)
  list(JOIN missing "\n  " missing)
  message(FATAL_ERROR "bakeoff-update-lesson: nothing copied; these are missing:\n  ${missing}\n"
                      "Run `cmake --build build --target bakeoff` first.")
endif()
foreach(from to IN ZIP_LISTS sources targets)
  file(COPY_FILE ${from} ${to})
  message(STATUS "copied ${from} to ${to}")
endforeach()
