# CMake generated Testfile for 
# Source directory: /work/main/tests
# Build directory: /work/main/build/tests
# 
# This file includes the relevant testing commands required for 
# testing this directory and lists subdirectories to be tested as well.
add_test(unit.test_sky "/work/main/build/tests/test_sky")
set_tests_properties(unit.test_sky PROPERTIES  ENVIRONMENT "ATMOS_SOURCE_DIR=/work/main;ATMOS_CLI=/work/main/build/atmos;ATMOS_TEST_TMP=/work/main/build/tests/tmp" LABELS "unit" _BACKTRACE_TRIPLES "/work/main/tests/CMakeLists.txt;24;add_test;/work/main/tests/CMakeLists.txt;0;")
add_test(asan.test_sky "/work/main/build/tests/test_sky_asan")
set_tests_properties(asan.test_sky PROPERTIES  ENVIRONMENT "ATMOS_SOURCE_DIR=/work/main;ATMOS_CLI=/work/main/build/atmos;ATMOS_TEST_TMP=/work/main/build/tests/tmp;ASAN_OPTIONS=detect_leaks=1:abort_on_error=1;UBSAN_OPTIONS=print_stacktrace=1" LABELS "asan" _BACKTRACE_TRIPLES "/work/main/tests/CMakeLists.txt;31;add_test;/work/main/tests/CMakeLists.txt;0;")
add_test(unit.test_sky_batch "/work/main/build/tests/test_sky_batch")
set_tests_properties(unit.test_sky_batch PROPERTIES  ENVIRONMENT "ATMOS_SOURCE_DIR=/work/main;ATMOS_CLI=/work/main/build/atmos;ATMOS_TEST_TMP=/work/main/build/tests/tmp" LABELS "unit" _BACKTRACE_TRIPLES "/work/main/tests/CMakeLists.txt;24;add_test;/work/main/tests/CMakeLists.txt;0;")
add_test(asan.test_sky_batch "/work/main/build/tests/test_sky_batch_asan")
set_tests_properties(asan.test_sky_batch PROPERTIES  ENVIRONMENT "ATMOS_SOURCE_DIR=/work/main;ATMOS_CLI=/work/main/build/atmos;ATMOS_TEST_TMP=/work/main/build/tests/tmp;ASAN_OPTIONS=detect_leaks=1:abort_on_error=1;UBSAN_OPTIONS=print_stacktrace=1" LABELS "asan" _BACKTRACE_TRIPLES "/work/main/tests/CMakeLists.txt;31;add_test;/work/main/tests/CMakeLists.txt;0;")
add_test(unit.test_sunpos "/work/main/build/tests/test_sunpos")
set_tests_properties(unit.test_sunpos PROPERTIES  ENVIRONMENT "ATMOS_SOURCE_DIR=/work/main;ATMOS_CLI=/work/main/build/atmos;ATMOS_TEST_TMP=/work/main/build/tests/tmp" LABELS "unit" _BACKTRACE_TRIPLES "/work/main/tests/CMakeLists.txt;24;add_test;/work/main/tests/CMakeLists.txt;0;")
add_test(asan.test_sunpos "/work/main/build/tests/test_sunpos_asan")
set_tests_properties(asan.test_sunpos PROPERTIES  ENVIRONMENT "ATMOS_SOURCE_DIR=/work/main;ATMOS_CLI=/work/main/build/atmos;ATMOS_TEST_TMP=/work/main/build/tests/tmp;ASAN_OPTIONS=detect_leaks=1:abort_on_error=1;UBSAN_OPTIONS=print_stacktrace=1" LABELS "asan" _BACKTRACE_TRIPLES "/work/main/tests/CMakeLists.txt;31;add_test;/work/main/tests/CMakeLists.txt;0;")
add_test(cli.sun "sh" "/work/main/tests/cli/sun.sh")
set_tests_properties(cli.sun PROPERTIES  ENVIRONMENT "ATMOS_SOURCE_DIR=/work/main;ATMOS_CLI=/work/main/build/atmos;ATMOS_TEST_TMP=/work/main/build/tests/tmp" LABELS "integration" _BACKTRACE_TRIPLES "/work/main/tests/CMakeLists.txt;41;add_test;/work/main/tests/CMakeLists.txt;0;")
