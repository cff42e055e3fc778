# Fails when DOC does not contain each of FILES (separated by "|") verbatim: docs that
# quote an example whole stay what the example is. Run with:
#   cmake -DDOC=doc.md "-DFILES=a.h|b.cpp" -P check_doc_quotes.cmake
file(READ "${DOC}" doc)
string(REPLACE "|" ";" FILES "${FILES}")
foreach(file ${FILES})
  file(READ "${file}" text)
  string(FIND "${doc}" "${text}" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "${DOC} no longer quotes ${file} verbatim; copy the file's current "
                        "text into its code block")
  endif()
endforeach()
