# lucent_add_programs(<target> HEADERS <module.h>...)
#
# Adds Lucent program modules to <target>: for each header, a generated C++ file that
# includes it (so its programs are compiled for the CPU backend and registered with the
# module it declares) and embeds its text and the text of the headers it includes by quoted
# paths (so the CUDA backend can compile it into the megakernel at run time). The header's
# quoted includes are looked up beside it, then in <target>'s include directories; Lucent's
# own "lucent/..." headers are never embedded again. Editing any of those headers
# re-embeds the module.
#
# For a STATIC library the generated files are added to the programs that link it (a static
# library's objects that nothing references would be dropped at link time, and with them
# the module's text); an OBJECT library, an executable or a shared library holds them itself.
#
# <target> links Lucent::lucent itself (the generated files include Lucent's headers).
# Part of the installed package (find_package(Lucent)) and of the build tree alike.
function(lucent_add_programs target)
  cmake_parse_arguments(PARSE_ARGV 1 ARG "" "" "HEADERS")
  if(NOT TARGET ${target})
    message(FATAL_ERROR "lucent_add_programs: '${target}' is not a target; create it first "
                        "(add_executable or add_library)")
  endif()
  if(NOT ARG_HEADERS)
    message(FATAL_ERROR "lucent_add_programs(${target}): no HEADERS given; name your program "
                        "module headers: lucent_add_programs(${target} HEADERS my_programs.h)")
  endif()
  if(TARGET Lucent::lucent_embed_module)
    set(tool Lucent::lucent_embed_module)  # the installed package
  elseif(TARGET lucent_embed_module)
    set(tool lucent_embed_module)  # Lucent's own build, or add_subdirectory / FetchContent
  else()
    message(FATAL_ERROR "lucent_add_programs: the lucent-embed-module tool is missing; "
                        "find_package(Lucent CONFIG REQUIRED) first")
  endif()

  get_target_property(type ${target} TYPE)
  set(outputs "")
  set(out_dir "${CMAKE_CURRENT_BINARY_DIR}/lucent_modules/${target}")
  file(MAKE_DIRECTORY "${out_dir}")
  set(include_dirs "$<TARGET_PROPERTY:${target},INCLUDE_DIRECTORIES>")
  foreach(header ${ARG_HEADERS})
    get_filename_component(header "${header}" ABSOLUTE)
    if(NOT EXISTS "${header}")
      message(FATAL_ERROR "lucent_add_programs(${target}): ${header} does not exist")
    endif()
    get_filename_component(stem "${header}" NAME_WE)
    string(MD5 path_hash "${header}")
    string(SUBSTRING "${path_hash}" 0 8 path_hash)
    set(output "${out_dir}/${stem}_${path_hash}.embed.cpp")
    set(depfile "${out_dir}/${stem}_${path_hash}.embed.d")
    add_custom_command(OUTPUT "${output}"
      COMMAND ${tool} --header "${header}" --output "${output}" --depfile "${depfile}"
              "$<$<BOOL:${include_dirs}>:--include-dir;$<JOIN:${include_dirs},;--include-dir;>>"
      DEPENDS "${header}" ${tool}
      DEPFILE "${depfile}"
      COMMENT "Embedding the program module ${header}"
      COMMAND_EXPAND_LISTS VERBATIM)
    if(type STREQUAL "STATIC_LIBRARY")
      target_sources(${target} INTERFACE "${output}")
    else()
      target_sources(${target} PRIVATE "${output}")
    endif()
    list(APPEND outputs "${output}")
  endforeach()
  if(type STREQUAL "STATIC_LIBRARY")
    # The programs that link <target> compile these files, in whatever directory they are
    # made; the rule that generates them is only in this one. So they are generated before
    # <target> is built, which every program linking it waits for (without this, a program
    # of another directory built first finds no rule to make them).
    set(generate "${target}_lucent_modules")
    set(n 1)
    while(TARGET "${generate}")
      math(EXPR n "${n} + 1")
      set(generate "${target}_lucent_modules_${n}")
    endwhile()
    add_custom_target(${generate} DEPENDS ${outputs})
    add_dependencies(${target} ${generate})
  endif()
endfunction()
