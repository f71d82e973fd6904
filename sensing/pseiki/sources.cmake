# PSEIKI (survey seed 003, section 4): the sources sensing/CMakeLists.txt compiles into spar::sensing.
set(SPAR_PSEIKI_SOURCES
  pseiki/hierarchical_evidence.cpp
  pseiki/collinearity.cpp
  pseiki/expected_scene.cpp
  pseiki/blackboard.cpp
  pseiki/labeler.cpp
  pseiki/grouper.cpp
  pseiki/merger.cpp
  pseiki/splitter.cpp
  pseiki/pose_correction.cpp
  pseiki/matcher.cpp
  pseiki/simulate.cpp
  pseiki/vision_json.cpp
  pseiki/internal/polygon.cpp)
