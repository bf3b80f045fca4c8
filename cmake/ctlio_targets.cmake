# Helpers shared by every part's CMakeLists.txt.

# ctlio_add_library(NAME <target> EXPORT_NAME <name> SOURCES ... [DEPS ...])
# A static library with the part's include/ folder, installed and exported as
# ctlio::<export name>. With no SOURCES it is an INTERFACE (header-only) target.
function(ctlio_add_library)
  cmake_parse_arguments(ARG "" "NAME;EXPORT_NAME;INCLUDE_DIR" "SOURCES;DEPS" ${ARGN})
  if(NOT ARG_INCLUDE_DIR)
    set(ARG_INCLUDE_DIR ${CMAKE_CURRENT_SOURCE_DIR}/include)
  endif()
  if(ARG_SOURCES)
    add_library(${ARG_NAME} ${ARG_SOURCES})
    set(scope PUBLIC)
    set_target_properties(${ARG_NAME} PROPERTIES POSITION_INDEPENDENT_CODE ON)
  else()
    add_library(${ARG_NAME} INTERFACE)
    set(scope INTERFACE)
  endif()
  add_library(ctlio::${ARG_EXPORT_NAME} ALIAS ${ARG_NAME})
  set_target_properties(${ARG_NAME} PROPERTIES EXPORT_NAME ${ARG_EXPORT_NAME})
  target_include_directories(${ARG_NAME} ${scope}
    $<BUILD_INTERFACE:${ARG_INCLUDE_DIR}> $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
  if(ARG_DEPS)
    target_link_libraries(${ARG_NAME} ${scope} ${ARG_DEPS})
  endif()
  install(TARGETS ${ARG_NAME} EXPORT ${CTLIO_EXPORT_SET}
          ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR})
endfunction()
