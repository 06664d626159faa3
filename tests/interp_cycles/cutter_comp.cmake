# Cutter radius compensation targets beside interp_cycles_test (which holds the core's tests).

# Compensation cost per move on dense input; not a test, run by hand (see the file's header).
add_executable(cutter_comp_bench cutter_comp_bench.cpp)
target_link_libraries(cutter_comp_bench PRIVATE interp)

# Compensation through the whole interpreter (atomic rejection, messages, multi-turn arcs).
add_executable(interp_crc_exec_test cutter_comp_exec_test.cpp)
target_link_libraries(interp_crc_exec_test PRIVATE interp GTest::gtest_main)
gtest_discover_tests(interp_crc_exec_test TEST_PREFIX "interp_cycles.")
