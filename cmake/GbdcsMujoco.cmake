# gbdcs_find_mujoco(): defines the one GLOBAL mujoco::mujoco target for every sim directory.
# GLOBAL because the imported target is in the PUBLIC link interface of gbdcs_sim_physics and
# gbdcs_sim_render, so every directory that links them (sim/*, app, tests) must see it.
# Debian's libmujoco-dev 2.2.2 exports /usr/include/libqhull_r/, which it does not install
# (that is libqhull-dev) and our code never needs: keep only the include paths that exist.
function(gbdcs_find_mujoco)
  if(TARGET mujoco::mujoco)
    return()
  endif()
  find_package(mujoco REQUIRED GLOBAL)
  get_target_property(includes mujoco::mujoco INTERFACE_INCLUDE_DIRECTORIES)
  set(existing "")
  foreach(dir IN LISTS includes)
    if(EXISTS "${dir}")
      list(APPEND existing "${dir}")
    endif()
  endforeach()
  set_target_properties(mujoco::mujoco PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${existing}")
endfunction()
