# ctest accel_isa_symbols.<variant> (tests/CMakeLists.txt): fails when an object of an
# instruction-set variant of the traversal defines an external symbol outside its own
# namespace lucent::accel::<VARIANT>. Such a symbol (a header's inline function the compiler
# did not inline, a template instance) is also defined, compiled for the baseline, by other
# objects, and the linker keeps one copy for the whole program: maybe this one, with AVX2 or
# AVX-512 instructions in it. The remedy is to inline it or to move it into the variant's
# namespace or an anonymous one.
#   cmake -DNM=nm -DVARIANT=isa_avx2 -DOBJECTS="a.o;b.o" -P check_isa_symbols.cmake
string(LENGTH "${VARIANT}" length)
set(prefix "_ZN6lucent5accel${length}${VARIANT}")  # the Itanium mangling of the namespace
set(bad "")
foreach(object ${OBJECTS})
  execute_process(COMMAND ${NM} --defined-only --extern-only ${object}
    OUTPUT_VARIABLE listing RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${NM} failed on ${object}")
  endif()
  string(REPLACE "\n" ";" lines "${listing}")
  foreach(line ${lines})
    if(line MATCHES "^[0-9a-fA-F]* *[A-Za-z] (.+)$")
      set(symbol "${CMAKE_MATCH_1}")
      string(FIND "${symbol}" "${prefix}" at)
      if(NOT at EQUAL 0)
        list(APPEND bad "${symbol}")
      endif()
    endif()
  endforeach()
endforeach()
if(bad)
  list(JOIN bad "\n  " text)
  message(FATAL_ERROR "${VARIANT} defines external symbols outside its namespace (see "
                      "cmake/check_isa_symbols.cmake):\n  ${text}")
endif()
message(STATUS "${VARIANT}: only its own entry points are external")
