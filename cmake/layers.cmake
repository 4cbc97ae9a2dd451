# The layers, as the build holds them: each folder's target may use only the
# folders it links (directly, or through their PUBLIC links). After every
# folder is added, morphoflow_layers() writes each folder's links into
# layer_links.cmake and adds the target `layers` (part of `all`), which runs
# check_layers.cmake over the sources: an #include "FOLDER/..." of a folder
# the includer does not link fails the build, naming the file and line.
# docs/architecture.md's table is compared with the same links by the test
# Architecture.LinksTable.

# FOLDER's targets (its libraries and executables), as `targets`.
function(_morphoflow_folder_targets folder out)
  get_property(targets DIRECTORY ${PROJECT_SOURCE_DIR}/${folder} PROPERTY BUILDSYSTEM_TARGETS)
  set(${out} ${targets} PARENT_SCOPE)
endfunction()

# The project folders a list of link items names (morphoflow::X, morphoflow_X, a target of folder X).
function(_morphoflow_link_folders items out)
  set(folders "")
  foreach(item IN LISTS items)
    if(item MATCHES "^morphoflow::([a-z_]+)$" OR item MATCHES "^morphoflow_([a-z_]+)$")
      set(target morphoflow_${CMAKE_MATCH_1})
      if(TARGET ${item})
        get_target_property(aliased ${item} ALIASED_TARGET)
        if(aliased)
          set(target ${aliased})
        else()
          set(target ${item})
        endif()
      endif()
      if(TARGET ${target})
        get_target_property(dir ${target} SOURCE_DIR)
        file(RELATIVE_PATH folder ${PROJECT_SOURCE_DIR} ${dir})
        list(APPEND folders ${folder})
      endif()
    endif()
  endforeach()
  list(REMOVE_DUPLICATES folders)
  set(${out} ${folders} PARENT_SCOPE)
endfunction()

function(morphoflow_layers)
  set(layers "")
  set(text "")
  set(sources "")
  foreach(folder IN LISTS ARGN)
    _morphoflow_folder_targets(${folder} targets)
    if(NOT targets)
      continue()  # (python/ without pybind11)
    endif()
    list(APPEND layers ${folder})
    set(links "")
    set(public "")
    foreach(t IN LISTS targets)
      get_target_property(type ${t} TYPE)
      if(type STREQUAL "UTILITY")
        continue()
      endif()
      if(NOT type STREQUAL "INTERFACE_LIBRARY")
        get_target_property(l ${t} LINK_LIBRARIES)
        if(l)
          list(APPEND links ${l})
        endif()
      endif()
      get_target_property(p ${t} INTERFACE_LINK_LIBRARIES)
      if(p)
        list(APPEND public ${p})
        list(APPEND links ${p})
      endif()
    endforeach()
    _morphoflow_link_folders("${links}" links)
    _morphoflow_link_folders("${public}" public)
    list(REMOVE_ITEM links ${folder})
    list(REMOVE_ITEM public ${folder})
    string(APPEND text "set(LINKS_${folder} ${links})\nset(PUBLIC_${folder} ${public})\n")
    file(GLOB_RECURSE found CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/${folder}/*.h ${PROJECT_SOURCE_DIR}/${folder}/*.cpp
         ${PROJECT_SOURCE_DIR}/${folder}/*.inc)
    list(APPEND sources ${found})
  endforeach()
  set(links_file ${PROJECT_BINARY_DIR}/layer_links.cmake)
  file(CONFIGURE OUTPUT ${links_file} CONTENT "set(MORPHOFLOW_LAYERS ${layers})\n${text}")
  add_custom_command(OUTPUT ${PROJECT_BINARY_DIR}/layers.checked
    COMMAND ${CMAKE_COMMAND} -DLINKS=${links_file} -DSOURCE=${PROJECT_SOURCE_DIR} -DMODE=includes
            -P ${PROJECT_SOURCE_DIR}/cmake/check_layers.cmake
    COMMAND ${CMAKE_COMMAND} -E touch ${PROJECT_BINARY_DIR}/layers.checked
    DEPENDS ${sources} ${links_file} ${PROJECT_SOURCE_DIR}/cmake/check_layers.cmake
    COMMENT "Checking that every #include points down the layers (cmake/layers.cmake)" VERBATIM)
  add_custom_target(layers ALL DEPENDS ${PROJECT_BINARY_DIR}/layers.checked)
endfunction()
