# Sources of the stress scenes, added to cps_scenes by demos/CMakeLists.txt.
set(CPS_STRESS_SCENE_SOURCES
  ${CMAKE_CURRENT_LIST_DIR}/stress_table.cpp
  ${CMAKE_CURRENT_LIST_DIR}/stress_common.cpp
  ${CMAKE_CURRENT_LIST_DIR}/mass_ratio.cpp
  ${CMAKE_CURRENT_LIST_DIR}/heavy_ball_grid.cpp
  ${CMAKE_CURRENT_LIST_DIR}/large_dt.cpp
  ${CMAKE_CURRENT_LIST_DIR}/spin.cpp
  ${CMAKE_CURRENT_LIST_DIR}/sphere_in_box.cpp
  ${CMAKE_CURRENT_LIST_DIR}/chain.cpp
  ${CMAKE_CURRENT_LIST_DIR}/scale.cpp
  ${CMAKE_CURRENT_LIST_DIR}/degenerate.cpp
  ${CMAKE_CURRENT_LIST_DIR}/random.cpp
  ${CMAKE_CURRENT_LIST_DIR}/hard_cases.cpp
)
