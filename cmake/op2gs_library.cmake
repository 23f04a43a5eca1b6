# One library per source folder, as COLMAP builds one per folder: the PUBLIC
# link lists are the layers (docs/architecture.md). A folder may include its
# own headers and those of the folders it links, directly or through them,
# and nothing else: an include that runs up the layers, or sideways into a
# folder it does not link, fails the build with a line naming the file.
#
#   op2gs_library(NAME FOLDER <folder> SOURCES <.cc ...>
#                 LAYERS <op2gs libraries below it> [PRIVATE <third-party targets>]
#                 [PUBLIC <third-party targets>])

set(OP2GS_CHECK_INCLUDES ${CMAKE_CURRENT_LIST_DIR}/check_includes.cmake)

function(op2gs_library name)
  cmake_parse_arguments(ARG "" "FOLDER" "SOURCES;LAYERS;PRIVATE;PUBLIC" ${ARGN})
  add_library(${name} STATIC ${ARG_SOURCES})
  target_include_directories(${name} PUBLIC ${PROJECT_SOURCE_DIR})
  target_link_libraries(${name} PUBLIC ${ARG_LAYERS} ${ARG_PUBLIC} PRIVATE ${ARG_PRIVATE})
  op2gs_precompiled_headers(${name})

  # The folders this one may include: its own and every folder below it.
  set(allowed ${ARG_FOLDER})
  foreach(layer IN LISTS ARG_LAYERS)
    get_property(below GLOBAL PROPERTY OP2GS_FOLDERS_${layer})
    list(APPEND allowed ${below})
  endforeach()
  list(REMOVE_DUPLICATES allowed)
  set_property(GLOBAL PROPERTY OP2GS_FOLDERS_${name} ${allowed})

  file(GLOB headers CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/${ARG_FOLDER}/*.h)
  set(files ${headers})
  foreach(source IN LISTS ARG_SOURCES)
    if(IS_ABSOLUTE ${source})  # generated in the build folder
      list(APPEND files ${source})
    else()
      list(APPEND files ${CMAKE_CURRENT_SOURCE_DIR}/${source})
    endif()
  endforeach()
  set(stamp ${CMAKE_CURRENT_BINARY_DIR}/${name}.includes_checked)
  string(REPLACE ";" "," allowed_arg "${allowed}")
  string(REPLACE ";" "," files_arg "${files}")
  add_custom_command(
    OUTPUT ${stamp}
    COMMAND ${CMAKE_COMMAND} -DLIBRARY=${name} "-DALLOWED=${allowed_arg}" "-DFILES=${files_arg}"
            -DROOT=${PROJECT_SOURCE_DIR} -DSTAMP=${stamp} -P ${OP2GS_CHECK_INCLUDES}
    DEPENDS ${files} ${OP2GS_CHECK_INCLUDES}
    COMMENT "Checking the includes of ${name} against its layers"
    VERBATIM)
  add_custom_target(${name}_includes DEPENDS ${stamp})
  add_dependencies(${name} ${name}_includes)
endfunction()
