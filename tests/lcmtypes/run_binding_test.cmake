# Runs WRITER to write an encoded configuration to OUT_FILE, then the decoder
# (DECODER with DECODER_ARGS, '|'-separated, OUT_FILE appended), and fails
# unless both print the same summary line.
#   cmake -DWRITER=... -DOUT_FILE=... -DDECODER=... -DDECODER_ARGS=a|b -P run_binding_test.cmake
execute_process(COMMAND ${WRITER} ${OUT_FILE} RESULT_VARIABLE rc OUTPUT_VARIABLE expected ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${WRITER} failed (${rc}): ${err}")
endif()
string(REPLACE "|" ";" args "${DECODER_ARGS}")
execute_process(COMMAND ${DECODER} ${args} ${OUT_FILE} RESULT_VARIABLE rc OUTPUT_VARIABLE actual ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${DECODER} failed (${rc}): ${err}")
endif()
string(STRIP "${expected}" expected)
string(STRIP "${actual}" actual)
message(STATUS "writer:  ${expected}")
message(STATUS "decoder: ${actual}")
if(NOT actual STREQUAL expected)
  message(FATAL_ERROR "the decoder disagrees with the writer")
endif()
