# Plants wrong-way includes in a scratch tree SCRATCH and runs the layering check CHECK on it: the
# check must fail and name every planted file; a right-way include must not be named.
#   cmake -DCHECK=cmake/check_layering.cmake -DSCRATCH=<dir> -P layering_planted.cmake
file(REMOVE_RECURSE "${SCRATCH}")
file(WRITE "${SCRATCH}/engine/core/units.h" "#include \"engine/system/system.h\"\n")  # inside engine
file(WRITE "${SCRATCH}/results/io/reader.cpp" "  #  include \"results/report/report.h\"\n")  # inside results
file(WRITE "${SCRATCH}/engine/scenario/drop.cpp" "#include \"results/io/trace_file.h\"\n")  # engine -> results
file(WRITE "${SCRATCH}/results/model/fit.cpp" "#include \"results/io/table.h\"\n#include \"engine/core/error.h\"\n")
execute_process(COMMAND ${CMAKE_COMMAND} -DROOT=${SCRATCH} -P ${CHECK} RESULT_VARIABLE rc ERROR_VARIABLE err
                OUTPUT_VARIABLE out)
if(rc EQUAL 0)
  message(FATAL_ERROR "the layering check passed a tree with wrong-way includes:\n${out}${err}")
endif()
foreach(planted engine/core/units.h results/io/reader.cpp engine/scenario/drop.cpp)
  string(FIND "${err}" "${planted}" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "the layering check did not name ${planted}:\n${err}")
  endif()
endforeach()
string(FIND "${err}" "results/model/fit.cpp" at)
if(NOT at EQUAL -1)
  message(FATAL_ERROR "the layering check named a right-way include (results/model -> results/io, engine):\n${err}")
endif()
file(REMOVE_RECURSE "${SCRATCH}")
message(STATUS "layering check: every planted wrong-way include named")
