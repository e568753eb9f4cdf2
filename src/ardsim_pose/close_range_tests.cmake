# Tests and benchmark of the close-range methods (close_range.cmake holds their sources). They render frames
# in-process with ardsim_lidar's LidarSimulator (EGL, llvmpipe without a GPU).
find_package(benchmark REQUIRED)
add_executable(bench_pose_close_range bench/close_range/bench_pose_close_range.cpp)
target_link_libraries(bench_pose_close_range ${PROJECT_NAME} ${ardsim_lidar_LIBRARIES} benchmark::benchmark)

# The golden set's generator (see test/close_range/make_golden.cpp for the command).
find_package(OpenCV REQUIRED COMPONENTS core imgcodecs)
add_executable(pose_close_range_make_golden test/close_range/make_golden.cpp)
target_link_libraries(pose_close_range_make_golden ${PROJECT_NAME} ${ardsim_lidar_LIBRARIES} ${OpenCV_LIBS})

if(CATKIN_ENABLE_TESTING)
  catkin_add_gtest(test_pose_close_range test/close_range/test_close_range.cpp test/close_range/test_mode_manager.cpp
                   test/close_range/test_golden.cpp test/close_range/test_handover.cpp
                   WORKING_DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR})
  target_link_libraries(test_pose_close_range ${PROJECT_NAME} ${ardsim_lidar_LIBRARIES} ${OpenCV_LIBS}
                        ${GTEST_MAIN_LIBRARIES})
  target_compile_definitions(test_pose_close_range PRIVATE
                             CLOSE_RANGE_GOLDEN_DIR="${CMAKE_CURRENT_SOURCE_DIR}/test/close_range/golden")
endif()
