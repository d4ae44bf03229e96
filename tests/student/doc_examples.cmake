# Builds every ```cpp block of a document that defines trax_main as a kernel outside the tree
# (find_package(tpsim)) and renders it, so the examples in the docs cannot rot:
#   cmake -DDOC=docs/kernel-api.md -DWORK=dir -DTPSIM_BUILD=dir -DTPSIM=tpsim -DSCENE=x.toml
#         -P doc_examples.cmake
cmake_minimum_required(VERSION 3.20)
file(READ "${DOC}" rest)
file(REMOVE_RECURSE "${WORK}")
set(cmake_lists "cmake_minimum_required(VERSION 3.20)\nproject(doc_examples LANGUAGES CXX)\n")
string(APPEND cmake_lists "find_package(tpsim REQUIRED)\n")
set(count 0)
# Walked with string(FIND) rather than a regex list: C++ is full of ';', CMake's list separator.
while(TRUE)
  string(FIND "${rest}" "```cpp\n" start)
  if(start EQUAL -1)
    break()
  endif()
  math(EXPR start "${start} + 7")
  string(SUBSTRING "${rest}" ${start} -1 rest)
  string(FIND "${rest}" "```" end)
  string(SUBSTRING "${rest}" 0 ${end} block)
  string(SUBSTRING "${rest}" ${end} -1 rest)
  if(block MATCHES "void trax_main\\(\\)")
    math(EXPR count "${count} + 1")
    file(WRITE "${WORK}/example_${count}.cpp" "${block}")
    string(APPEND cmake_lists "add_trax_kernel(example_${count} SOURCES example_${count}.cpp)\n")
  endif()
endwhile()
if(count EQUAL 0)
  message(FATAL_ERROR "${DOC} has no ```cpp block defining trax_main")
endif()
file(WRITE "${WORK}/CMakeLists.txt" "${cmake_lists}")

execute_process(COMMAND "${CMAKE_COMMAND}" -S "${WORK}" -B "${WORK}/build"
                        "-Dtpsim_DIR=${TPSIM_BUILD}" RESULT_VARIABLE rc OUTPUT_VARIABLE log ERROR_VARIABLE log)
if(rc EQUAL 0)
  execute_process(COMMAND "${CMAKE_COMMAND}" --build "${WORK}/build"
                  RESULT_VARIABLE rc OUTPUT_VARIABLE log ERROR_VARIABLE log)
endif()
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "an example of ${DOC} does not build as a kernel (${WORK}):\n${log}")
endif()
foreach(n RANGE 1 ${count})
  foreach(engine "--timing;none" "--native")
    execute_process(COMMAND "${TPSIM}" render "${SCENE}" ${engine} -k
                            "${WORK}/build/kernels/example_${n}.elf" -o "${WORK}/example_${n}.png"
                    RESULT_VARIABLE rc OUTPUT_VARIABLE log ERROR_VARIABLE log)
    if(NOT rc EQUAL 0)
      message(FATAL_ERROR "example ${n} of ${DOC} (${WORK}/example_${n}.cpp) fails: ${log}")
    endif()
  endforeach()
endforeach()
message("${count} examples of ${DOC} built and rendered")
