# TraxKernel.cmake: build TRaX kernels (docs/kernel-api.md).
#
#   add_trax_kernel(NAME SOURCES a.cpp [b.cpp ...])
#
# in tpsim's own tree, or in any other project after find_package(tpsim) (tpsimConfig.cmake in
# tpsim's build directory includes this file; `tpsim new-kernel DIR` writes such a project).
#
# makes
#   ${CMAKE_BINARY_DIR}/kernels/NAME.elf            target NAME_elf (in ALL): RV32IMF, for tpsim
#   ${CMAKE_BINARY_DIR}/kernels/libNAME_native.so   target NAME_native: the native twin, exporting
#                                                   tpsim_native_run() (kernel/native_twin.h)
# Before linking the ELF, the kernel's objects are checked and the build fails with a message
# naming the symbol and the function using it if the kernel needs doubles, the heap, virtual
# dispatch, exceptions or any library function TRaX does not have.
#
# The same file is the checker when run as a script (that is how the build calls it):
#   cmake -DTRAX_CHECK_KERNEL=NAME -DTRAX_CHECK_OBJECTS=a.o;b.o -DTRAX_CHECK_STAMP=file
#         -DTRAX_NM=... -DTRAX_OBJDUMP=... -DTRAX_CXXFILT=... -P TraxKernel.cmake

if(CMAKE_SCRIPT_MODE_FILE AND DEFINED TRAX_CHECK_KERNEL)
  # ---- The checker ---------------------------------------------------------------------------
  cmake_minimum_required(VERSION 3.20)

  # Demangles a list of symbols in one llvm-cxxfilt call.
  function(_trax_demangle out)
    set(text "")
    if(ARGN)
      string(REPLACE ";" "\n" input "${ARGN}")
      file(WRITE "${TRAX_CHECK_STAMP}.symbols" "${input}\n")
      execute_process(COMMAND "${TRAX_CXXFILT}" INPUT_FILE "${TRAX_CHECK_STAMP}.symbols"
                      OUTPUT_VARIABLE text OUTPUT_STRIP_TRAILING_WHITESPACE)
      string(REPLACE "\n" ";" text "${text}")
    endif()
    set(${out} "${text}" PARENT_SCOPE)
  endfunction()

  function(_trax_nm out obj mode)
    execute_process(COMMAND "${TRAX_NM}" ${mode} --format=just-symbols "${obj}"
                    OUTPUT_VARIABLE text RESULT_VARIABLE rc ERROR_VARIABLE err)
    if(NOT rc EQUAL 0)
      message(FATAL_ERROR "TRaX kernel check: llvm-nm failed on ${obj}: ${err}")
    endif()
    string(REGEX REPLACE "\n$" "" text "${text}")
    string(REPLACE "\n" ";" text "${text}")
    set(${out} "${text}" PARENT_SCOPE)
  endfunction()

  set(defined "memcpy;memmove;memset;memcmp")  # kernel/runtime/runtime.cpp
  set(undefined "")
  set(vtables "")
  foreach(obj IN LISTS TRAX_CHECK_OBJECTS)
    _trax_nm(def "${obj}" --defined-only)
    _trax_nm(undef "${obj}" --undefined-only)
    list(APPEND defined ${def})
    list(APPEND undefined ${undef})
    foreach(sym IN LISTS def undef)
      if(sym MATCHES "^_ZTV")
        list(APPEND vtables "${sym}")
      endif()
    endforeach()
  endforeach()
  list(REMOVE_DUPLICATES undefined)
  list(REMOVE_ITEM undefined ${defined})
  list(REMOVE_DUPLICATES vtables)

  # Which functions reference a symbol, and from which source line: with -ffunction-sections
  # every function has its own section .text.<mangled name>; the disassembly with -l names the
  # source line (of the inlined code, too) above the instructions, -r the relocations below them.
  set(users_of_all "")
  foreach(obj IN LISTS TRAX_CHECK_OBJECTS)
    # (ERROR_QUIET: llvm-objdump 14 warns that it cannot apply the DWARF's R_RISCV_SET8 and
    # friends; the line table it needs does not use them.)
    execute_process(COMMAND "${TRAX_OBJDUMP}" -d -r -l --no-show-raw-insn "${obj}"
                    OUTPUT_VARIABLE listing ERROR_QUIET)
    # ';' starts the line comments and would split CMake's list; brackets would stop it splitting.
    string(REPLACE ";" "#" listing "${listing}")
    string(REPLACE "[" "(" listing "${listing}")
    string(REPLACE "]" ")" listing "${listing}")
    string(REPLACE "\n" ";" listing "${listing}")
    set(function "")
    set(where "")
    foreach(line IN LISTS listing)
      if(line MATCHES "^Disassembly of section (\\.text\\.(.+)|.*):$")
        set(function "${CMAKE_MATCH_2}")
        set(where "")
      elseif(line MATCHES "^# (.*/)?([^/]+):([0-9]+)$")
        set(where " at ${CMAKE_MATCH_2}:${CMAKE_MATCH_3}")
      elseif(function AND line MATCHES "^[ \t]+[0-9a-f]+: +R_[A-Z0-9_]+[ \t]+([^ +]+)")
        set(sym "${CMAKE_MATCH_1}")
        list(APPEND "users_of_${sym}" "${function}|${where}")
        list(APPEND users_of_all "${sym}")
      endif()
    endforeach()
  endforeach()

  # "sym, called from f() at a.cpp:5, g() at b.cpp:9" for the message.
  function(_trax_describe out sym)
    _trax_demangle(name "${sym}")
    set(users "${users_of_${sym}}")
    if(users)
      list(REMOVE_DUPLICATES users)
      set(functions "")
      set(places "")
      foreach(user IN LISTS users)
        string(REPLACE "|" ";" user "${user}")
        list(GET user 0 function)
        list(LENGTH user fields)
        set(place "")
        if(fields GREATER 1)
          list(GET user 1 place)
        endif()
        list(APPEND functions "${function}")
        list(APPEND places "${place}")
      endforeach()
      _trax_demangle(functions ${functions})
      set(described "")
      foreach(function place IN ZIP_LISTS functions places)
        list(APPEND described "${function}${place}")
      endforeach()
      list(JOIN described ", " described)
      set(name "${name}, called from ${described}")
    endif()
    set(${out} "${name}" PARENT_SCOPE)
  endfunction()

  set(problems "")
  set(kernel "kernel '${TRAX_CHECK_KERNEL}'")
  if(NOT "trax_main" IN_LIST defined)
    list(APPEND problems "${kernel} defines no entry point: write `void trax_main() { ... }`")
  endif()
  foreach(sym IN LISTS undefined)
    _trax_describe(what "${sym}")
    if(sym MATCHES "^__[a-z]+[dt]f[0-9]?$" OR sym MATCHES "^__[a-z]+(sf|si|di)(df|tf)[0-9]?$"
       OR sym MATCHES "^__[a-z]+[dt]f(sf|si|di)[0-9]?$")
      list(APPEND problems "${kernel} uses double-precision arithmetic (${what}): TRaX has no double unit — use float and write literals as 1.0f")
    elseif(sym MATCHES "^(malloc|calloc|realloc|free|aligned_alloc|posix_memalign|_Zn[wa].*|_Zd[la].*)$")
      list(APPEND problems "${kernel} uses the heap (${what}): TRaX kernels have no heap — use fixed-size arrays on the stack or data in global memory")
    elseif(sym MATCHES "^(__cxa_pure_virtual|__cxa_deleted_virtual)$")
      list(APPEND problems "${kernel} uses virtual functions (${what}): TRaX kernels have no virtual dispatch — use a type tag and a switch, or templates")
    elseif(sym MATCHES "^(__cxa_.*exception|__cxa_throw|__cxa_rethrow|__cxa_begin_catch|__cxa_end_catch|__gxx_personality_v0|_Unwind_.*)$")
      list(APPEND problems "${kernel} uses exceptions (${what}): TRaX kernels cannot throw — return a status value instead")
    else()
      list(APPEND problems "${kernel} calls a function TRaX kernels do not have (${what}): there is no C/C++ library — use the helpers in trax.hpp (trax_sqrt, trax_min ...) or write the function yourself")
    endif()
  endforeach()
  if(vtables)
    _trax_demangle(names ${vtables})
    list(JOIN names ", " names)
    list(APPEND problems "${kernel} uses virtual functions (${names}): TRaX kernels have no virtual dispatch — use a type tag and a switch, or templates")
  endif()

  if(problems)
    foreach(problem IN LISTS problems)
      message(NOTICE "error: ${problem}")
    endforeach()
    file(REMOVE "${TRAX_CHECK_STAMP}")
    message(FATAL_ERROR "TRaX ${kernel} rejected (see the error lines above).")
  endif()
  file(WRITE "${TRAX_CHECK_STAMP}" "ok\n")
  return()
endif()

# ---- The build rules ---------------------------------------------------------------------------

set(TRAX_KERNEL_DIR "${CMAKE_CURRENT_LIST_DIR}/../kernel" CACHE INTERNAL "")
get_filename_component(TRAX_KERNEL_DIR "${TRAX_KERNEL_DIR}" ABSOLUTE)
set(TRAX_KERNEL_CHECKER "${CMAKE_CURRENT_LIST_FILE}" CACHE INTERNAL "")

find_program(TRAX_CLANG NAMES clang-14 clang REQUIRED)
find_program(TRAX_LLD NAMES ld.lld-14 ld.lld REQUIRED)
find_program(TRAX_NM NAMES llvm-nm-14 llvm-nm REQUIRED)
find_program(TRAX_OBJDUMP NAMES llvm-objdump-14 llvm-objdump REQUIRED)
find_program(TRAX_CXXFILT NAMES llvm-cxxfilt-14 llvm-cxxfilt REQUIRED)

# The guest ABI. -mno-relax: ld.lld 14 cannot relax RISC-V code. -msmall-data-limit=0: no
# gp-relative small-data sections (clang 14 would put FP constants in writable .sdata).
set(TRAX_KERNEL_TARGET_FLAGS
    --target=riscv32-unknown-elf -march=rv32imf -mabi=ilp32f -mno-relax -msmall-data-limit=0 -g)
# -ffreestanding implies -fno-builtin: no library calls are assumed, yet clang may still emit
# memcpy/memset/memmove/memcmp for struct copies and clears, which kernel/runtime provides.
# -ffunction-sections lets the checker name the function that uses a forbidden symbol.
# -ffp-contract=off on both sides so the native twin rounds exactly like the guest.
# -Werror=implicit-float-conversion catches a double result narrowed to float (`float x = p * 0.5`),
# -Werror=double-promotion a float widened to double (`f * 0.5`); an int turned into a float
# (`(x + 0.5f) / width`, -Wimplicit-int-float-conversion, part of the first) is how pixel maths
# is written and exact below 2^24, so it is allowed. For the stack bound
# (sim/core/stack_bound.hpp): -fstack-size-section records every function's frame, -Werror=vla
# keeps every frame's size fixed, -fno-jump-tables leaves no jump whose target is unknown.
set(TRAX_KERNEL_CXX_FLAGS
    ${TRAX_KERNEL_TARGET_FLAGS} -std=c++20 -O2 -ffreestanding -fno-exceptions -fno-rtti
    -fno-math-errno -ffp-contract=off -nostdlib -ffunction-sections -fdata-sections
    -fstack-size-section -fno-jump-tables -Wall -Wextra -Werror=double-promotion
    -Werror=implicit-float-conversion -Wno-implicit-int-float-conversion -Werror=vla
    "-I${TRAX_KERNEL_DIR}")

# Compiles one guest source to ${obj}, tracking header dependencies.
function(_trax_compile obj src)
  get_filename_component(src "${src}" ABSOLUTE)
  if(src MATCHES "\\.[sS]$")
    set(flags ${TRAX_KERNEL_TARGET_FLAGS})
  else()
    set(flags ${TRAX_KERNEL_CXX_FLAGS} ${ARGN})
  endif()
  get_filename_component(dir "${obj}" DIRECTORY)
  # The project's own files by their path in it, tpsim's runtime by its path in tpsim's tree.
  file(RELATIVE_PATH shown "${CMAKE_SOURCE_DIR}" "${src}")
  if(shown MATCHES "^\\.\\./")
    file(RELATIVE_PATH shown "${TRAX_KERNEL_DIR}/.." "${src}")
  endif()
  add_custom_command(
    OUTPUT "${obj}"
    COMMAND "${CMAKE_COMMAND}" -E make_directory "${dir}"
    COMMAND "${TRAX_CLANG}" ${flags} -MD -MF "${obj}.d" -c "${src}" -o "${obj}"
    DEPENDS "${src}"
    DEPFILE "${obj}.d"
    COMMENT "TRaX kernel: compiling ${shown}"
    VERBATIM)
endfunction()

function(add_trax_kernel NAME)
  cmake_parse_arguments(PARSE_ARGV 1 ARG "" "" "SOURCES")
  if(NOT ARG_SOURCES)
    message(FATAL_ERROR "add_trax_kernel(${NAME}): no SOURCES given")
  endif()
  set(out "${CMAKE_BINARY_DIR}/kernels")
  set(work "${out}/${NAME}.dir")

  set(objects "")
  foreach(src IN LISTS ARG_SOURCES)
    get_filename_component(base "${src}" NAME)
    set(obj "${work}/${base}.o")
    _trax_compile("${obj}" "${src}")
    list(APPEND objects "${obj}")
  endforeach()
  _trax_compile("${work}/runtime/start.o" "${TRAX_KERNEL_DIR}/runtime/start.S")
  # -fno-builtin keeps memcpy's loop from being compiled into a call to memcpy.
  _trax_compile("${work}/runtime/runtime.o" "${TRAX_KERNEL_DIR}/runtime/runtime.cpp" -fno-builtin)

  add_custom_command(
    OUTPUT "${work}/check.stamp"
    COMMAND "${CMAKE_COMMAND}" "-DTRAX_CHECK_KERNEL=${NAME}" "-DTRAX_CHECK_OBJECTS=${objects}"
            "-DTRAX_CHECK_STAMP=${work}/check.stamp" "-DTRAX_NM=${TRAX_NM}"
            "-DTRAX_OBJDUMP=${TRAX_OBJDUMP}" "-DTRAX_CXXFILT=${TRAX_CXXFILT}"
            -P "${TRAX_KERNEL_CHECKER}"
    DEPENDS ${objects} "${TRAX_KERNEL_CHECKER}"
    COMMENT "TRaX kernel ${NAME}: checking for doubles, heap, virtual functions, exceptions"
    VERBATIM)

  set(script "${TRAX_KERNEL_DIR}/runtime/kernel.ld")
  add_custom_command(
    OUTPUT "${out}/${NAME}.elf"
    COMMAND "${TRAX_LLD}" -T "${script}" --gc-sections -o "${out}/${NAME}.elf"
            "${work}/runtime/start.o" ${objects} "${work}/runtime/runtime.o"
    DEPENDS "${work}/check.stamp" "${work}/runtime/start.o" "${work}/runtime/runtime.o"
            ${objects} "${script}"
    COMMENT "TRaX kernel ${NAME}: linking kernels/${NAME}.elf"
    VERBATIM)
  add_custom_target(${NAME}_elf ALL DEPENDS "${out}/${NAME}.elf")

  # The native twin: the same sources, compiled for the host.
  add_library(${NAME}_native SHARED ${ARG_SOURCES} "${TRAX_KERNEL_DIR}/runtime/native_twin.cpp")
  target_include_directories(${NAME}_native PRIVATE "${TRAX_KERNEL_DIR}")
  target_compile_features(${NAME}_native PRIVATE cxx_std_20)
  # -g always, so gdb finds the source; the optimisation follows the build type (a folder made
  # by `tpsim new-kernel` is a Debug build: -O0). Without contraction host float arithmetic is
  # IEEE single precision at any -O, so the twin stays bit-identical to the ELF either way.
  target_compile_options(${NAME}_native PRIVATE -g -ffp-contract=off -fno-math-errno)
  set_target_properties(${NAME}_native PROPERTIES
    CXX_VISIBILITY_PRESET hidden
    VISIBILITY_INLINES_HIDDEN ON
    LIBRARY_OUTPUT_DIRECTORY "${out}")
endfunction()
