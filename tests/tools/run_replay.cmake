# Runs `cia402 replay ARGS < INPUT` and compares its standard output with EXPECTED, byte for byte.
# With EXPECT_FAILURE the exit status must be non-zero (and the output still matches EXPECTED).
set(replay_args ${ARGS})  # a CMake list, passed on whole by -DARGS=...
execute_process(
  COMMAND "${CIA402}" replay ${replay_args}
  INPUT_FILE "${INPUT}"
  OUTPUT_VARIABLE out
  ERROR_VARIABLE err
  RESULT_VARIABLE rc)
if(EXPECT_FAILURE)
  if(rc EQUAL 0)
    message(FATAL_ERROR "cia402 replay ${ARGS} exited 0; expected an error exit")
  endif()
  if(err STREQUAL "")
    message(FATAL_ERROR "cia402 replay ${ARGS} failed without a message on stderr")
  endif()
elseif(NOT rc EQUAL 0)
  message(FATAL_ERROR "cia402 replay ${ARGS} exited ${rc}: ${err}")
endif()
file(READ "${EXPECTED}" expected)
if(NOT out STREQUAL expected)
  message(FATAL_ERROR "cia402 replay ${ARGS} < ${INPUT}\n--- got:\n${out}--- expected:\n${expected}")
endif()
