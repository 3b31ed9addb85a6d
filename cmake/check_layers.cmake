# Fails when a file includes a header of a room in a higher layer than its own.
#   cmake -DROOT=<source dir> -P cmake/check_layers.cmake
#
# The layers, bottom to top, as framework/CMakeLists.txt builds them. A file may include its own
# layer and any layer below it, never one above: the framework never includes a plug-in, and the
# torch-free plug-ins (dataset builders, non-learned baselines) never include a libtorch room.
# The command-line program sits above the plug-ins but, like all of framework/, never includes
# one: it reaches them through their registries (tasks, datasets, binders, models).
set(SKINLAB_LAYERS
  "framework/core"
  "framework/geometry framework/binders"
  "framework/distances"
  "framework/data"
  "framework/infer framework/predict_cli"
  "datasets baselines/bone_heat baselines/geo_voxel"
  "framework/tensors framework/graph framework/losses framework/models"
  "framework/task framework/train framework/eval framework/report framework/predict"
  "experiments baselines/neuroskinning baselines/rignet_skin"
  "framework/cli")

if(NOT ROOT)
  message(FATAL_ERROR "check_layers.cmake: pass -DROOT=<source dir>")
endif()

# The layer index of a path relative to ROOT (a file or an include), -1 when it is in no room.
function(layer_of path out)
  set(index 0)
  foreach(layer ${SKINLAB_LAYERS})
    string(REPLACE " " ";" rooms "${layer}")
    foreach(room ${rooms})
      string(LENGTH "${room}/" n)
      string(SUBSTRING "${path}" 0 ${n} prefix)
      if(prefix STREQUAL "${room}/")
        set(${out} ${index} PARENT_SCOPE)
        return()
      endif()
    endforeach()
    math(EXPR index "${index} + 1")
  endforeach()
  set(${out} -1 PARENT_SCOPE)
endfunction()

file(GLOB_RECURSE files RELATIVE ${ROOT}
     ${ROOT}/framework/*.[hc]pp ${ROOT}/experiments/*.[hc]pp
     ${ROOT}/baselines/*.[hc]pp ${ROOT}/datasets/*.[hc]pp)
set(violations 0)
foreach(file ${files})
  layer_of("${file}" own)
  if(own EQUAL -1)
    message(SEND_ERROR "${file}: in no layer; add its folder to cmake/check_layers.cmake")
    math(EXPR violations "${violations} + 1")
    continue()
  endif()
  file(STRINGS ${ROOT}/${file} lines REGEX "^[ \t]*#[ \t]*include[ \t]*\"")
  foreach(line ${lines})
    string(REGEX REPLACE "^[ \t]*#[ \t]*include[ \t]*\"([^\"]*)\".*" "\\1" header "${line}")
    layer_of("${header}" theirs)
    if(file MATCHES "^framework/" AND header MATCHES "^(experiments|baselines|datasets)/")
      message(SEND_ERROR "${file}: includes the plug-in header \"${header}\"; the framework "
                         "reaches plug-ins only through their registries")
      math(EXPR violations "${violations} + 1")
    elseif(theirs GREATER own)
      list(GET SKINLAB_LAYERS ${own} own_rooms)
      list(GET SKINLAB_LAYERS ${theirs} their_rooms)
      message(SEND_ERROR "${file}: includes \"${header}\", a higher layer (${their_rooms}) "
                         "than its own (${own_rooms})")
      math(EXPR violations "${violations} + 1")
    endif()
  endforeach()
endforeach()
list(LENGTH files count)
if(violations GREATER 0)
  message(FATAL_ERROR "${violations} include(s) reach up a layer")
endif()
message(STATUS "layers: ${count} files, no include reaches up a layer")
