# ctest -R mpi.failures: a rank that fails ends the run on every rank with one message
# naming the rank and the cause, a non-zero exit, and no image. Each case starts its ranks
# with mpirun's MPMD form (`A : B`), so one rank gets other arguments.
file(MAKE_DIRECTORY ${WORK})
set(common render --backend cpu --threads 1 --quiet)

function(expect_failure name expected)
  set(out_file ${WORK}/failure-${name}.pfm)
  file(REMOVE ${out_file})
  execute_process(COMMAND ${MPIRUN} ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out
    ERROR_VARIABLE err)
  if(rc EQUAL 0)
    message(FATAL_ERROR "${name}: mpirun exited 0:\n${out}${err}")
  endif()
  # Semicolons in a message would split CMake's list: count lines with them replaced.
  string(REPLACE ";" "," text "${out}${err}")
  string(REGEX MATCHALL "lucent render: error: [^\n]*" messages "${text}")
  list(LENGTH messages count)
  if(NOT count EQUAL 1)
    message(FATAL_ERROR "${name}: ${count} error messages, not one:\n${out}${err}")
  endif()
  if(NOT messages MATCHES "${expected}")
    message(FATAL_ERROR "${name}: the message is not '${expected}':\n${messages}")
  endif()
  if(EXISTS ${out_file})
    message(FATAL_ERROR "${name}: ${out_file} was written")
  endif()
  file(GLOB temporaries ${WORK}/*.tmp* ${WORK}/.failure-*)
  if(temporaries)
    message(FATAL_ERROR "${name}: temporary files left: ${temporaries}")
  endif()
  message(STATUS "${name}: ${messages}")
endfunction()

# A scene file that is missing on one node (rank 2's path does not exist).
set(out ${WORK}/failure-scene.pfm)
expect_failure(scene "rank 2: .*missing-on-this-node.obj"
  -np 2 ${LUCENT} ${common} --sample pathtracer --size 64x48 --out ${out} :
  -np 1 ${LUCENT} ${common} --sample pathtracer --scene ${WORK}/missing-on-this-node.obj
        --size 64x48 --out ${out})
# A device that cannot run on one rank (rank 1 asks for a GPU that is not there).
set(out ${WORK}/failure-device.pfm)
expect_failure(device "rank 1: Context: device cuda:15"
  -np 1 ${LUCENT} ${common} --sample whitted --size 64x48 --out ${out} :
  -np 2 ${LUCENT} ${common} --sample whitted --devices 15 --size 64x48 --out ${out})
# Ranks whose host code diverged (rank 2 renders another size): an error, not a wrong image.
set(out ${WORK}/failure-diverged.pfm)
expect_failure(diverged "ranks diverged: the launch of rank 2 differs"
  -np 2 ${LUCENT} ${common} --sample whitted --size 64x48 --out ${out} :
  -np 1 ${LUCENT} ${common} --sample whitted --size 64x40 --out ${out})
