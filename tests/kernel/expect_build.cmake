# Builds one target of the reject project and checks the outcome:
#   cmake -DBUILD_DIR=... -DTARGET=... -DEXPECT=<regex> -DSHOULD_FAIL=ON|OFF -P expect_build.cmake
execute_process(COMMAND "${CMAKE_COMMAND}" --build "${BUILD_DIR}" --target "${TARGET}"
                OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
set(log "${out}${err}")
message("${log}")
if(SHOULD_FAIL AND rc EQUAL 0)
  message(FATAL_ERROR "${TARGET} built, but the kernel should have been rejected")
elseif(NOT SHOULD_FAIL AND NOT rc EQUAL 0)
  message(FATAL_ERROR "${TARGET} failed to build, but the kernel is legal")
endif()
if(NOT log MATCHES "${EXPECT}")
  message(FATAL_ERROR "${TARGET}: the build output does not match: ${EXPECT}")
endif()
