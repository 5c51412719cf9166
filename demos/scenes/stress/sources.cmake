# Sources of the stress scenes, added to cps_scenes by demos/CMakeLists.txt.
set(CPS_STRESS_SCENE_SOURCES
  ${CMAKE_CURRENT_LIST_DIR}/stress_table.cpp
)
