# Close-range pose methods (pyramid, docking ring, their shared adapter fit) and the mode manager: core sources
# for the package library. Tests and benchmarks are in close_range_tests.cmake, included once the library exists.
list(APPEND POSE_CORE_SOURCES src/close_range/adapter_fit.cpp src/close_range/ring_detector.cpp
     src/close_range/pyramid.cpp src/close_range/mode_manager.cpp)
