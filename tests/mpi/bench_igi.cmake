# ctest -R mpi.bench_igi: `mpirun -np 3 lucent bench igi` needs no flag: its frames' launches
# are spread over the ranks, and rank 0 alone prints (one JSON object).
execute_process(COMMAND ${MPIRUN} -np 3 -x LUCENT_MULTI_TRACE=1 ${LUCENT} bench igi --threads 1
          --size 64x48 --frames 1 --vpls 8 --json
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "mpirun -np 3 lucent bench igi: exit ${rc}:\n${out}${err}")
endif()
string(JSON configurations ERROR_VARIABLE json_error LENGTH "${out}" rows)
if(json_error)
  message(FATAL_ERROR "not one JSON object (did several ranks print?): ${json_error}\n${out}")
endif()
if(configurations LESS 4)
  message(FATAL_ERROR "${configurations} rows, expected the 4 configurations:\n${out}")
endif()
if(NOT err MATCHES "distributed: entry [^\n]*rank 2: [0-9]+ pieces")
  message(FATAL_ERROR "no launch was spread over the 3 ranks:\n${err}")
endif()
message(STATUS "bench igi on 3 ranks: ${configurations} rows")
