# TraxKernel.cmake: add_trax_kernel() (filled in with the kernel toolchain)
