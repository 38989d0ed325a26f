# `clothlab bench roofline --quick --csv F`: the machine's limits are printed as positive figures;
# the CSV has the documented header and a row per cloth size whose numbers are positive and
# finite; each floor is the larger of its compute and bandwidth floors; the engine's step is no
# faster than its floor, and the spring loop alone (bench speed's kernel row) no faster than the
# compute floor. The threads' part is there: the copy on 2 threads, a row per size of
# the 1 and 2 thread steps with what two threads lose and to what, and of the model of 8 and 16
# cores, which says its socket bandwidth is assumed. No timing is asserted by value.
#
# Why the engine cannot beat the floor: every spring of a step takes a square root and then a
# division (the reference kernel), and the compute floor is what those two cost per spring at the
# best throughput this machine showed in a loop that does nothing else, compiled as the engine's
# loops are. (The bandwidth floor counts only bytes the step must move, at the rate of a copy over
# as many bytes as the step touches; at these sizes the compute floor is the larger.) Noise: the
# floor is the fastest of its repeats and the engine the median of its own, and a busy machine
# only slows a repeat, so load raises the ratio rather than lowering it. The bound is therefore 1.
cmake_policy(SET CMP0057 NEW)  # if(... IN_LIST ...)
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
execute_process(COMMAND ${CLOTHLAB} bench roofline --quick --csv roofline.csv
                WORKING_DIRECTORY ${WORK}
                RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT code EQUAL 0)
  message(FATAL_ERROR "bench roofline failed with ${code}\n${out}${err}")
endif()

set(number "[0-9]+\\.[0-9]+")
foreach(operation "square root" "division" "square root, then division")
  if(NOT out MATCHES "\n  ${operation} +(${number}) +(${number}) +(${number}) +(${number})\n")
    message(FATAL_ERROR "no row of four figures for '${operation}':\n${out}")
  endif()
  foreach(index 1 2 3 4)
    if(NOT CMAKE_MATCH_${index} GREATER 0)
      message(FATAL_ERROR "'${operation}': figure ${index} is ${CMAKE_MATCH_${index}}:\n${out}")
    endif()
  endforeach()
endforeach()
foreach(stream copy read)
  if(NOT out MATCHES "streaming ${stream}[^\n]* (${number}) GB/s\n")
    message(FATAL_ERROR "no bandwidth for the streaming ${stream}:\n${out}")
  endif()
  if(NOT CMAKE_MATCH_1 GREATER 0)
    message(FATAL_ERROR "the streaming ${stream} moved ${CMAKE_MATCH_1} GB/s:\n${out}")
  endif()
endforeach()

if(NOT out MATCHES "the same copy on 2 threads[^\n]* (${number}) GB/s \\((${number}) times 1 thread")
  message(FATAL_ERROR "no bandwidth for the streaming copy on 2 threads:\n${out}")
endif()

include(${CMAKE_CURRENT_LIST_DIR}/bench_csv.cmake)
string(CONCAT header "n,particles,springs,data_bytes,bytes_per_spring,copy_gb_per_s,"
       "compute_floor_ns,bandwidth_floor_ns,floor_ns,engine_ns,engine_over_floor,"
       "engine_1_thread_ns,engine_2_threads_ns,speedup_2,lost_serial,lost_energy_check,lost_wake,"
       "lost_imbalance,lost_work,model_2_ns,model_8_ns,model_16_ns,kernel_ns,engine_over_kernel")
# What two threads lose of a speed-up of 2 are differences of measurements: the serial part, the
# wake and the slower work may come out below 0 by noise (two halves of a small cloth can each
# fit a cache the whole does not), so they are finite, of either sign. Every time is positive.
bench_csv_rows(${WORK}/roofline.csv "${header}" 0 lines 14 16 18)
set(sizes "")
foreach(line ${lines})
  string(REPLACE "," ";" fields "${line}")
  list(GET fields 0 n)
  list(GET fields 6 compute)
  list(GET fields 7 bandwidth)
  list(GET fields 8 floor)
  list(GET fields 9 engine)
  list(GET fields 10 ratio)
  list(GET fields 22 kernel)
  list(APPEND sizes ${n})
  # The spring loop alone does every spring's square root and division too, at the vector width
  # the floor's loop has, and more besides: it cannot beat the compute floor either.
  if(kernel LESS compute)
    message(FATAL_ERROR "n = ${n}: the spring loop alone (${kernel} ns per spring) beat the "
                        "compute floor (${compute} ns)\n${out}")
  endif()
  # The floor is the larger of the two: the same number, so the same digits in the CSV.
  set(larger ${compute})
  if(bandwidth GREATER compute)
    set(larger ${bandwidth})
  endif()
  if(NOT floor STREQUAL larger)
    message(FATAL_ERROR "n = ${n}: floor ${floor} ns is not the larger of compute ${compute} "
                        "and bandwidth ${bandwidth}")
  endif()
  if(ratio LESS 1)
    message(FATAL_ERROR "n = ${n}: the engine (${engine} ns per spring) beat its floor (${floor} "
                        "ns): engine/floor = ${ratio}\n${out}")
  endif()
  # The table prints the same row: N, springs, ..., and the ratio at its end.
  if(NOT out MATCHES "\n +${n} +[0-9]+ [^\n]*(compute|bandwidth) +${number} +${number} +${number}\n")
    message(FATAL_ERROR "no table row for N = ${n}:\n${out}")
  endif()
endforeach()
# The threads' table and the model's, a row per size: N, then figures; the model names what bounds
# 16 cores and where the socket's bandwidth would cap the scaling.
foreach(n ${sizes})
  if(NOT out MATCHES "\n +${n} +${number} +${number} +${number} +-?${number} +${number} +-?${number} +${number} +-?${number}\n")
    message(FATAL_ERROR "no row of the threads' table for N = ${n}:\n${out}")
  endif()
  set(figures " +${number} +${number} +${number} +${number}")
  if(NOT out MATCHES "\n +${n}${figures}${figures} +(compute|bandwidth|serial\\+wake) +at [0-9]+ cores\n")
    message(FATAL_ERROR "no row of the model of 8 and 16 cores for N = ${n}:\n${out}")
  endif()
endforeach()
foreach(phrase "ASSUMED, not measured" "peak memory of this run [0-9]+ MB"
               "kernel: the spring loop alone [^\n]*\n[^\n]*: [0-9.]+ ns per spring, [0-9.]+ times the compute floor")
  if(NOT out MATCHES "${phrase}")
    message(FATAL_ERROR "the printout does not say '${phrase}':\n${out}")
  endif()
endforeach()
if(NOT sizes STREQUAL "16;32")
  message(FATAL_ERROR "roofline.csv has the sizes '${sizes}'; expected 16 and 32")
endif()
