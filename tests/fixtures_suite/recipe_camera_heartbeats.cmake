# `gbdcs vision` on a recipe camera whose video is not cached yet: while it renders, the worker
# says so in heartbeats (not healthy, "preparing the camera"), and every heartbeat it sends,
# before and after the render, is one the server accepts (vision_heartbeat). A heartbeat the
# server rejects is silence to its supervisor, which kills a worker it has not heard from.
# GBDCS, RECIPE, WORK.
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
# The live video loops forever: stopped after a few seconds (SIGTERM, SIGKILL 5 s later).
execute_process(COMMAND ${CMAKE_COMMAND} -E env GBDCS_FIXTURE_CACHE=${WORK}/cache
                        timeout -k 5 8 ${GBDCS} vision --source "recipe:${RECIPE}?live=1" --heartbeat 0.05
                OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
string(REPLACE "\n" ";" lines "${out}")
set(preparing 0)
set(running 0)
set(n 0)
foreach(line IN LISTS lines)
  if(NOT line MATCHES "^{\"")
    continue()
  endif()
  string(JSON type ERROR_VARIABLE json_error GET "${line}" type)
  if(json_error)
    message(FATAL_ERROR "not one JSON document per line (${json_error}): ${line}")
  endif()
  if(NOT type STREQUAL "heartbeat")
    continue()
  endif()
  string(JSON reason GET "${line}" reason)
  if(reason MATCHES "^preparing the camera")
    math(EXPR preparing "${preparing} + 1")
    string(JSON healthy GET "${line}" healthy)
    if(healthy)
      message(FATAL_ERROR "a heartbeat while the camera is prepared says healthy: ${line}")
    endif()
    if(preparing GREATER 5)  # the first few are enough to check
      continue()
    endif()
  else()
    math(EXPR running "${running} + 1")
    if(running GREATER 2)
      continue()
    endif()
  endif()
  math(EXPR n "${n} + 1")
  file(WRITE ${WORK}/heartbeat_${n}.json "${line}")
  execute_process(COMMAND ${GBDCS} schema validate vision_heartbeat ${WORK}/heartbeat_${n}.json
                  OUTPUT_VARIABLE vout ERROR_VARIABLE verr RESULT_VARIABLE vrc)
  if(NOT vrc EQUAL 0)
    message(FATAL_ERROR "the worker sent a heartbeat the server rejects: ${vout}${verr}\n${line}")
  endif()
endforeach()
if(preparing EQUAL 0)
  message(FATAL_ERROR "no \"preparing the camera\" heartbeat while the recipe rendered (exit ${rc}): ${err}\n${out}")
endif()
message(STATUS "${preparing} heartbeats while preparing, ${running} after; ${n} validated")
