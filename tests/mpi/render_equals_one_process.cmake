# ctest -R mpi.render: `lucent render --sample SAMPLE` once alone and once under
# `MPIRUN -np 3`; the two .pfm files (32-bit float, no metadata) must be equal byte for byte,
# and the distributed run must have spread its launches over the ranks (rank 0's trace lines).
file(MAKE_DIRECTORY ${WORK})
# EXTRA: more render flags (e.g. --denoise), also naming the files. RANK_ENV: a VAR=value
# for the ranks (mpirun -x); EXPECT: a regular expression rank 0's trace must match.
set(one ${WORK}/${SAMPLE}${EXTRA}${RANK_ENV}-one.pfm)
set(three ${WORK}/${SAMPLE}${EXTRA}${RANK_ENV}-three.pfm)
file(REMOVE ${one} ${three})
set(args render --sample ${SAMPLE} --backend cpu --threads 1 --size 64x48 --quiet ${EXTRA})
execute_process(COMMAND ${LUCENT} ${args} --out ${one} RESULT_VARIABLE rc ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "one process: exit ${rc}: ${err}")
endif()
set(rank_env -x LUCENT_MULTI_TRACE=1)
if(RANK_ENV)
  list(APPEND rank_env -x ${RANK_ENV})
endif()
execute_process(COMMAND ${MPIRUN} -np 3 ${rank_env} ${LUCENT} ${args} --out ${three}
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "mpirun -np 3: exit ${rc}: ${out}${err}")
endif()
# Rank 0's trace: a line per spread launch, each rank's share.
string(REGEX MATCHALL "distributed: entry [^\n]*" launches "${err}")
list(LENGTH launches spread)
if(spread EQUAL 0)
  message(FATAL_ERROR "mpirun -np 3: no launch was spread over the ranks:\n${err}")
endif()
# Each line lists the three ranks' shares (how many pieces each took depends on timing).
if(NOT err MATCHES "\\[rank 0: [0-9]+ pieces[^\n]*\\[rank 1: [0-9]+ pieces[^\n]*\\[rank 2: ")
  message(FATAL_ERROR "mpirun -np 3: the trace does not list three ranks:\n${err}")
endif()
if(EXPECT AND NOT err MATCHES "${EXPECT}")
  message(FATAL_ERROR "mpirun -np 3: the trace does not match '${EXPECT}':\n${err}")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${one} ${three} RESULT_VARIABLE differ)
if(NOT differ EQUAL 0)
  message(FATAL_ERROR "${SAMPLE}: the image of 3 ranks differs from one process's")
endif()
message(STATUS "${SAMPLE}: ${spread} launches spread over 3 ranks, image equal to one process's")
