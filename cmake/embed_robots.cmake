# Writes a C++ source holding every robots/*.json, and every robots/*.urdf a robot file may name,
# as a string (run by the build, see src/CMakeLists.txt). Inputs: ROBOTS_DIR, OUTPUT.
file(GLOB robot_files RELATIVE "${ROBOTS_DIR}" "${ROBOTS_DIR}/*.json" "${ROBOTS_DIR}/*.urdf")
list(SORT robot_files)
set(body "")
foreach(name IN LISTS robot_files)
  file(READ "${ROBOTS_DIR}/${name}" text)
  string(APPEND body "    {\"${name}\", R\"rccx_robot(${text})rccx_robot\"},\n")
endforeach()
file(WRITE "${OUTPUT}.tmp" "// Generated from robots/*.json and *.urdf by cmake/embed_robots.cmake; do not edit.
#include \"rccx/kinematics/embedded_robots.hpp\"

#include <array>

namespace rccx::kin::detail {

namespace {
const EmbeddedRobot kRobots[] = {
${body}};
}  // namespace

std::span<const EmbeddedRobot> embedded_robots() noexcept { return kRobots; }

}  // namespace rccx::kin::detail
")
execute_process(COMMAND ${CMAKE_COMMAND} -E copy_if_different "${OUTPUT}.tmp" "${OUTPUT}")
