# The host layers in CMake: host_sim/layers.txt read into one library per folder.
#
# Build-time enforcement: each jg_<folder> publishes an include directory that holds only
# <folder> itself (a symbolic link in the build tree, build/<preset>/host_layers/<folder>/),
# not host_sim/ whole. A translation unit therefore sees its own folder and, through the
# libraries it links, the folders it may use and theirs: an include of a folder outside that
# set (an upward include, a back-edge, a side step to an unrelated folder) fails to compile.
# An include of a folder reached only transitively still compiles; scripts/check_layers.py
# (CTest static.layers) rejects it, naming the file and line.

# jg_read_host_layers(<file> <out-var>): the folders, lowest first, into <out-var>; each
# folder's deps into JG_HOST_DEPS_<folder>. Stops the configure on a malformed table, a dep
# that is not listed above its user, or a host_sim/ folder with sources but no line.
function(jg_read_host_layers table out)
  set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${table})
  file(STRINGS ${table} lines)
  set(folders "")
  foreach(line IN LISTS lines)
    if(line MATCHES "^[ \t]*(#|$)")
      continue()
    endif()
    if(NOT line MATCHES "^([a-z0-9_]+):[ \t]*(.*)$")
      message(FATAL_ERROR "${table}: not 'folder: deps...': '${line}'")
    endif()
    set(folder ${CMAKE_MATCH_1})
    string(REGEX REPLACE "[ \t]+" ";" deps "${CMAKE_MATCH_2}")
    list(REMOVE_ITEM deps "")
    foreach(dep IN LISTS deps)
      if(NOT dep MATCHES "^(firmware|hal)$" AND NOT dep IN_LIST folders)
        message(FATAL_ERROR "${table}: ${folder} lists ${dep}, which is not a line above it "
                            "(a folder may use only lower layers)")
      endif()
    endforeach()
    list(APPEND folders ${folder})
    set(JG_HOST_DEPS_${folder} ${deps} PARENT_SCOPE)
  endforeach()
  get_filename_component(root ${table} DIRECTORY)
  # Re-globbed at every build, so a new folder's first .cpp reconfigures and meets this check.
  file(GLOB all_sources CONFIGURE_DEPENDS ${root}/*/*.cpp)
  file(GLOB children LIST_DIRECTORIES true RELATIVE ${root} ${root}/*)
  foreach(child IN LISTS children)
    file(GLOB child_sources ${root}/${child}/*.cpp ${root}/${child}/*.hpp)
    if(IS_DIRECTORY ${root}/${child} AND child_sources AND NOT child IN_LIST folders)
      message(FATAL_ERROR "host_sim/${child} has sources but no line in ${table}: "
                          "place it in the layer table (and docs/architecture.md)")
    endif()
  endforeach()
  set(${out} ${folders} PARENT_SCOPE)
endfunction()

# jg_host_layer_sources(<folder> <out-var>): the folder's .cpp files.
function(jg_host_layer_sources folder out)
  file(GLOB sources CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/${folder}/*.cpp)
  set(${out} ${sources} PARENT_SCOPE)
endfunction()

# jg_host_layer_links(<target> <folder> <PUBLIC|PRIVATE|INTERFACE>): <target> linked to what
# <folder>'s line lists. A listed folder that does not exist (yet) is skipped.
function(jg_host_layer_links target folder scope)
  foreach(dep IN LISTS JG_HOST_DEPS_${folder})
    if(dep STREQUAL "firmware")
      target_link_libraries(${target} ${scope} jg_core_headers)
    elseif(dep STREQUAL "hal")
      target_link_libraries(${target} ${scope} jg_hal_headers)
    elseif(TARGET jg_${dep})
      target_link_libraries(${target} ${scope} jg_${dep})
    endif()
  endforeach()
  # The folder's own include directory (see the top of this file).
  set(dir ${CMAKE_BINARY_DIR}/host_layers/${folder})
  file(MAKE_DIRECTORY ${dir})
  file(CREATE_LINK ${CMAKE_CURRENT_SOURCE_DIR}/${folder} ${dir}/${folder} SYMBOLIC)
  target_include_directories(${target} ${scope} ${dir})
  target_link_libraries(${target} ${scope} jg_host_common)
endfunction()

# jg_host_layer_library(<folder>): jg_<folder>, static (or INTERFACE for a header-only
# folder), with its table links. Nothing for a listed folder that does not exist.
function(jg_host_layer_library folder)
  if(NOT IS_DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR}/${folder})
    return()
  endif()
  jg_host_layer_sources(${folder} sources)
  if(sources)
    add_library(jg_${folder} STATIC ${sources})
    target_link_libraries(jg_${folder} PRIVATE jg_host_flags)
    jg_host_layer_links(jg_${folder} ${folder} PUBLIC)
  else()
    add_library(jg_${folder} INTERFACE)
    jg_host_layer_links(jg_${folder} ${folder} INTERFACE)
  endif()
endfunction()
