# `quadlod report` (issue 22): the page is one self-contained HTML file, so the CLI carries its
# assets — three.js (npm, pinned by package-lock.json, installed by `npm ci` in scripts/bootstrap)
# and the viewer script / style — compiled into the binary by cmake/embed_file.cmake.
set(QUADLOD_THREE_JS ${PROJECT_SOURCE_DIR}/node_modules/three/build/three.module.min.js)
if(NOT EXISTS ${QUADLOD_THREE_JS})
  message(FATAL_ERROR "quadlod report needs three.js: run `npm ci` in ${PROJECT_SOURCE_DIR} "
                      "(scripts/bootstrap does), or configure with -DQUADLOD_HTML_REPORT=OFF")
endif()
set(QUADLOD_REPORT_ASSETS
    "${QUADLOD_THREE_JS}|quadlod_asset_three_js"
    "${PROJECT_SOURCE_DIR}/apps/quadlod/report/viewer.js|quadlod_asset_viewer_js"
    "${PROJECT_SOURCE_DIR}/apps/quadlod/report/viewer.css|quadlod_asset_viewer_css")
foreach(asset IN LISTS QUADLOD_REPORT_ASSETS)
  string(REPLACE "|" ";" parts "${asset}")
  list(GET parts 0 input)
  list(GET parts 1 name)
  set(output ${CMAKE_BINARY_DIR}/generated/${name}.cpp)
  add_custom_command(OUTPUT ${output}
    COMMAND ${CMAKE_COMMAND} -DINPUT=${input} -DOUTPUT=${output} -DNAME=${name}
            -P ${PROJECT_SOURCE_DIR}/cmake/embed_file.cmake
    DEPENDS ${input} ${PROJECT_SOURCE_DIR}/cmake/embed_file.cmake
    COMMENT "Embedding ${name}")
  target_sources(quadlod_cli PRIVATE ${output})
  set_source_files_properties(${output} PROPERTIES SKIP_PRECOMPILE_HEADERS ON)
endforeach()
target_compile_definitions(quadlod_cli PRIVATE QUADLOD_HTML_REPORT=1)
