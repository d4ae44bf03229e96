# add_guest_program(<elf> SOURCE <file> LINKER_SCRIPT <ld> [FLAGS <flag>...] [DEPENDS <file>...])
#
# Cross-compiles one bare-metal RV32IMF test program (assembly or C, no runtime) with the
# machine's clang into <elf>. Tests use these to exercise the simulator below the kernel API;
# kernels proper are built with add_trax_kernel() (TraxKernel.cmake).
find_program(TPSIM_GUEST_CC NAMES clang-14 clang REQUIRED)

function(add_guest_program elf)
  cmake_parse_arguments(PARSE_ARGV 1 ARG "" "SOURCE;LINKER_SCRIPT" "FLAGS;DEPENDS")
  get_filename_component(dir ${elf} DIRECTORY)
  get_filename_component(name ${elf} NAME_WE)
  add_custom_command(
    OUTPUT ${elf}
    COMMAND ${CMAKE_COMMAND} -E make_directory ${dir}
    COMMAND ${TPSIM_GUEST_CC} --target=riscv32-unknown-elf -march=rv32imf -mabi=ilp32f -nostdlib
            -ffreestanding -fno-math-errno -ffp-contract=off -fuse-ld=lld -mno-relax -O1 -g
            -Wl,-T,${ARG_LINKER_SCRIPT} ${ARG_FLAGS} ${ARG_SOURCE} -o ${elf}
    DEPENDS ${ARG_SOURCE} ${ARG_LINKER_SCRIPT} ${ARG_DEPENDS}
    COMMENT "Cross-compiling guest program ${name}"
    VERBATIM)
endfunction()
