target_sources(jg_core PRIVATE ${CMAKE_CURRENT_LIST_DIR}/observer_instances.cpp)
