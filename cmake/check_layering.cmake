# The layering of gravsweep's libraries: a folder may include only the folders below it.
#   engine/  -> (nothing of the project)      db/ -> (nothing of the project)
#   spec/    -> engine/core (ConfigError)     results/ -> engine/, db/, spec/
#   scheduler/ -> everything
# gravsweep_check_layering(<source dir>) stops with FATAL_ERROR naming each file and include
# that points the wrong way. Run as a script (cmake -DROOT=<dir> -P check_layering.cmake) from CTest.
function(gravsweep_check_layering root)
  set(problems "")
  foreach(pair "engine:scheduler/|results/|db/|spec/" "db:scheduler/|results/|engine/|spec/"
               "spec:scheduler/|results/|db/" "results:scheduler/")
    string(REPLACE ":" ";" parts "${pair}")
    list(GET parts 0 folder)
    list(GET parts 1 forbidden)
    file(GLOB_RECURSE files "${root}/${folder}/*.h" "${root}/${folder}/*.cpp" "${root}/${folder}/*.in")
    foreach(f IN LISTS files)
      file(STRINGS "${f}" lines REGEX "^[ \t]*#[ \t]*include[ \t]*[\"<](${forbidden})")
      foreach(l IN LISTS lines)
        file(RELATIVE_PATH rel "${root}" "${f}")
        string(STRIP "${l}" l)
        string(APPEND problems "\n  ${rel}: ${l} (${folder}/ must not include ${forbidden})")
      endforeach()
    endforeach()
  endforeach()
  if(problems)
    message(FATAL_ERROR "layering: includes against the dependency direction (scheduler -> results -> spec -> engine; results -> db):${problems}")
  endif()
endfunction()

if(CMAKE_SCRIPT_MODE_FILE AND DEFINED ROOT)
  gravsweep_check_layering("${ROOT}")
  message(STATUS "layering: ok")
endif()
