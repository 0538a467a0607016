# Debian's libmujoco-dev 2.2.2 lists /usr/include/libqhull_r/ among mujoco::mujoco's include
# directories, which only libqhull-dev provides and MuJoCo's public headers do not need; CMake
# refuses a target that names a missing directory. Keep only those that exist. Included after
# find_package(mujoco) by the build and by the installed package (rccxConfig.cmake).
if(TARGET mujoco::mujoco)
  get_target_property(_rccx_mujoco_dirs mujoco::mujoco INTERFACE_INCLUDE_DIRECTORIES)
  set(_rccx_mujoco_kept "")
  foreach(_rccx_dir IN LISTS _rccx_mujoco_dirs)
    if(EXISTS "${_rccx_dir}")
      list(APPEND _rccx_mujoco_kept "${_rccx_dir}")
    endif()
  endforeach()
  set_target_properties(mujoco::mujoco PROPERTIES INTERFACE_INCLUDE_DIRECTORIES
                                                  "${_rccx_mujoco_kept}")
endif()
