# BMFR fit and whole-chain timing at 1280×720 (bench/bmfr_bench.cpp).
if(TARGET fovea_pipeline)
  add_executable(fovea_bench_bmfr ${CMAKE_CURRENT_LIST_DIR}/bmfr_bench.cpp)
  target_link_libraries(fovea_bench_bmfr PRIVATE fovea_pipeline benchmark::benchmark)
endif()

# Screen footprint of the BMFR blocks on a Visual-Polar grid (bench/bmfr_footprint.cpp).
add_executable(fovea_bmfr_footprint ${CMAKE_CURRENT_LIST_DIR}/bmfr_footprint.cpp)
target_link_libraries(fovea_bmfr_footprint PRIVATE fovea_core)
