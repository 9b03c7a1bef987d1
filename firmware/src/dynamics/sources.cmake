target_sources(jg_core PRIVATE ${CMAKE_CURRENT_LIST_DIR}/momentum_instances.cpp)
