# Run-time dispatch of the CPU triangle traversal. src/accel/triangle_traverse.cpp (single
# rays) and src/accel/triangle_stream.cpp (ray streams) are the only hot loops that gain
# much from instruction sets beyond the portable baseline, so they are compiled once per
# variant below, each copy's entry points in namespace
# lucent::accel::isa_<variant> (LUCENT_ISA_VARIANT), and src/accel/cpu_isa.cpp picks the
# best one the CPU runs at the first query (LUCENT_CPU_ISA=scalar|avx2|avx512 overrides it).
#
# Included from CMakeLists.txt after the glob of the library's sources and before
# add_library(lucent): it takes the traversal out of LUCENT_CORE_SOURCES and puts the
# variants' objects in.
#
#   scalar  the build's own flags with the SIMD paths compiled out (LUCENT_ACCEL_SCALAR):
#           any CPU; what the tests accel_scalar.* run (tests/CMakeLists.txt)
#   avx2    -march=x86-64-v3 (AVX2, FMA, BMI1/2, LZCNT, MOVBE, F16C): Haswell, Zen 1 and
#           later; the whole level rather than -mavx2 -mfma, as BMI's tzcnt and blsr are
#           in every child-mask loop, and the dispatcher checks for the same level
#   avx512  -march=x86-64-v4 (v3 and AVX-512 F, VL, BW, DQ, CD): the occlusion rays'
#           compressed push of the hit children (__AVX512VL__). The code is 256 bits wide
#           by design; -mprefer-vector-width=256 keeps the compiler's own vectorization
#           there too, off the 512-bit units that lower some CPUs' clocks.
#
# The variants see the library's include directories and definitions (the layout of
# TriangleAccel::Impl they read must be the one the build wrote; nothing in it depends on
# the instruction set), and each copy defines no external symbol but its entry points:
# the test accel_isa_symbols checks that with nm.

set(LUCENT_TRAVERSE_SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/src/accel/triangle_traverse.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/src/accel/triangle_stream.cpp)
list(REMOVE_ITEM LUCENT_CORE_SOURCES ${LUCENT_TRAVERSE_SOURCES})

set(LUCENT_ISA_VARIANTS scalar)
set(LUCENT_ISA_OPTIONS_scalar "")
set(LUCENT_ISA_DEFINES_scalar LUCENT_ACCEL_SCALAR=1)
if(CMAKE_SYSTEM_PROCESSOR MATCHES "^(x86_64|AMD64|amd64)$")
  list(APPEND LUCENT_ISA_VARIANTS avx2 avx512)
  # -mno-avx512f: -march=native (LUCENT_NATIVE) expands to explicit -mavx512* flags, which a
  # later -march does not take back.
  set(LUCENT_ISA_OPTIONS_avx2 -march=x86-64-v3 -mno-avx512f)
  set(LUCENT_ISA_OPTIONS_avx512 -march=x86-64-v4 -mprefer-vector-width=256)
endif()

foreach(isa ${LUCENT_ISA_VARIANTS})
  add_library(lucent_isa_${isa} OBJECT ${LUCENT_TRAVERSE_SOURCES})
  # As the library's own sources are compiled, then the variant's flags (a later -march
  # wins over LUCENT_NATIVE's -march=native or the baseline's).
  target_include_directories(lucent_isa_${isa} PRIVATE
    $<TARGET_PROPERTY:lucent,INCLUDE_DIRECTORIES>)
  target_compile_definitions(lucent_isa_${isa} PRIVATE
    $<TARGET_PROPERTY:lucent,COMPILE_DEFINITIONS> LUCENT_ISA_VARIANT=isa_${isa}
    ${LUCENT_ISA_DEFINES_${isa}})
  target_compile_options(lucent_isa_${isa} PRIVATE ${LUCENT_ISA_OPTIONS_${isa}})
  list(APPEND LUCENT_CORE_SOURCES $<TARGET_OBJECTS:lucent_isa_${isa}>)
  string(TOUPPER ${isa} ISA)
  set_property(SOURCE src/accel/cpu_isa.cpp APPEND PROPERTY COMPILE_DEFINITIONS
    LUCENT_ISA_HAVE_${ISA}=1)
endforeach()
