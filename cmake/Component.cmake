# cnc_add_component(NAME SOURCE): one shared object per HAL component, dropped
# into the directory the loader searches by default.
function(cnc_add_component name source)
  add_library(comp_${name} MODULE ${source})
  set_target_properties(comp_${name} PROPERTIES
    OUTPUT_NAME ${name} PREFIX ""
    LIBRARY_OUTPUT_DIRECTORY ${CNC_COMPONENT_DIR}
    CXX_VISIBILITY_PRESET hidden)
  target_link_libraries(comp_${name} PRIVATE hal_api ${ARGN})
  set_property(GLOBAL APPEND PROPERTY CNC_COMPONENTS comp_${name})
endfunction()
