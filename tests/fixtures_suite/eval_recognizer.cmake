# `gbdcs eval --recognizer FILE`: the options reach the recogniser (a fold limit of 179 deg
# leaves no finger folded, so the thumbs-up's true landmarks no longer read THUMB_UP), in both
# file forms (RuleBasedOptions, or a pipeline options file's "recognizer" key); a bad value
# stops the run with exit 2, naming the file and the key.
file(MAKE_DIRECTORY ${WORK})
file(WRITE ${WORK}/strict.json "{\"finger_folded_min_curl_deg\": 179}")
file(WRITE ${WORK}/pipeline.json "{\"recognizer\": {\"finger_folded_min_curl_deg\": 179}}")
file(WRITE ${WORK}/bad.json "{\"finger_folded_min_curl_deg\": \"ninety\"}")

function(truth_accuracy options out_var)
  execute_process(COMMAND ${GBDCS} eval --json ${ARGN} ${FIXTURE}
                  OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "gbdcs eval ${options} exited ${rc}: ${err}")
  endif()
  string(JSON truth GET "${out}" truth_deliberate_accuracy)
  set(${out_var} ${truth} PARENT_SCOPE)
endfunction()

truth_accuracy("(defaults)" defaults)
if(NOT defaults EQUAL 1)
  message(FATAL_ERROR "with the default options the true landmarks read ${defaults}, expected 1")
endif()
foreach(file strict.json pipeline.json)
  truth_accuracy(${file} strict --recognizer ${WORK}/${file})
  if(NOT strict LESS 0.5)
    message(FATAL_ERROR "--recognizer ${file}: the true landmarks read ${strict} with a 179 deg fold limit; the options did not reach the recogniser")
  endif()
endforeach()

execute_process(COMMAND ${GBDCS} eval --json --recognizer ${WORK}/bad.json ${FIXTURE}
                OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
if(NOT rc EQUAL 2 OR NOT err MATCHES "bad.json: RuleBasedOptions: 'finger_folded_min_curl_deg' must be a number")
  message(FATAL_ERROR "a bad --recognizer file: exit ${rc}, \"${err}\"; expected exit 2 naming the file and the key")
endif()
message(STATUS "true landmarks read ${defaults} with the defaults, ${strict} with a 179 deg fold limit")
