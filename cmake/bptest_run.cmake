# bptest_run.cmake - run one test program for ctest the way tests/run_all.sh
# does: from the repository root (the tests open tests/data/ by relative
# path), showing its output, and passing only when it exits 0 AND its last
# "BPTEST <passed> <failed>" line reports no failure.  A crash, a nonzero
# exit or a missing BPTEST line fails the test.
#
#   cmake -DPROGRAM=<test program> -DWORKDIR=<repository root> -P bptest_run.cmake
if(NOT PROGRAM OR NOT WORKDIR)
  message(FATAL_ERROR "bptest_run.cmake: give -DPROGRAM=... and -DWORKDIR=...")
endif()
# test_threads writes its scratch OBJ files to build/tests/ (the Makefile's
# build directory, which .gitignore ignores): make sure it exists.
file(MAKE_DIRECTORY "${WORKDIR}/build/tests")
execute_process(COMMAND "${PROGRAM}" WORKING_DIRECTORY "${WORKDIR}"
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
message("${out}")
string(REGEX MATCHALL "BPTEST [0-9]+ [0-9]+" lines "${out}")
if(NOT lines)
  message(FATAL_ERROR "${PROGRAM}: exit status '${rc}', no BPTEST line: failed")
endif()
list(GET lines -1 last)
if(NOT last MATCHES "^BPTEST [0-9]+ 0$")
  message(FATAL_ERROR "${PROGRAM}: ${last}: failed")
endif()
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${PROGRAM}: exit status '${rc}' after '${last}': failed")
endif()
