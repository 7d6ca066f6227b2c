# Runs `cia402 simulate FILE` and checks its exit status and, when given, a regular expression on its
# standard output or error. With SAME_TRACES it runs twice, writing CSV, JSONL, VCD and SVG each
# time, and requires the files of both runs to be identical byte for byte.
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}")
set(runs 1)
if(SAME_TRACES)
  set(runs 2)
endif()
foreach(run RANGE 1 ${runs})
  foreach(ext csv jsonl vcd)
    execute_process(
      COMMAND "${CIA402}" simulate "${FILE}" --trace "${WORK}/run${run}.${ext}"
              --plot "${WORK}/run${run}.svg"
      OUTPUT_VARIABLE out
      ERROR_VARIABLE err
      RESULT_VARIABLE rc)
    if(NOT rc EQUAL EXIT)
      message(FATAL_ERROR "cia402 simulate ${FILE} exited ${rc}, expected ${EXIT}\n${out}\n${err}")
    endif()
    if(STDOUT AND NOT out MATCHES "${STDOUT}")
      message(FATAL_ERROR "standard output does not match '${STDOUT}':\n${out}")
    endif()
    if(STDERR AND NOT err MATCHES "${STDERR}")
      message(FATAL_ERROR "standard error does not match '${STDERR}':\n${err}")
    endif()
    if(EXIT EQUAL 2 AND EXISTS "${WORK}/run${run}.${ext}")
      file(READ "${WORK}/run${run}.${ext}" written)
      if(NOT written STREQUAL "")
        message(FATAL_ERROR "a refused scenario wrote a trace")
      endif()
    endif()
  endforeach()
endforeach()
if(SAME_TRACES)
  foreach(ext csv jsonl vcd svg)
    file(SHA256 "${WORK}/run1.${ext}" first)
    file(SHA256 "${WORK}/run2.${ext}" second)
    file(SIZE "${WORK}/run1.${ext}" size)
    if(NOT first STREQUAL second OR size EQUAL 0)
      message(FATAL_ERROR "the ${ext} files of two runs differ (or are empty)")
    endif()
  endforeach()
endif()
