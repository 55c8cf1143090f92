# Regenerates the demo motion and checks the committed samples/data copy is
# byte for byte what the generator writes (the demo inputs stay honest).
# MODE (optional): the generator's motion flag, e.g. --jump or --shoulder.
execute_process(COMMAND ${GEN} ${MODE} ${OUT} RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "generate_demo_data failed with ${rc}")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${OUT} ${REF} RESULT_VARIABLE same)
if(NOT same EQUAL 0)
  message(FATAL_ERROR "${REF} differs from what generate_demo_data writes (${OUT}); regenerate it")
endif()
