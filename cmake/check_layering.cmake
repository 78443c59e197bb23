# The layering of gravsweep's libraries: a folder may include only the folders below it.
#   engine/  -> (nothing of the project)      db/ -> (nothing of the project)
#   spec/    -> engine/core (ConfigError)     results/ -> engine/, db/, spec/
#   scheduler/ -> everything
# Inside a library the folders are layered too, lowest first; a folder may include only itself and
# the folders before it:
#   engine/:  core geometry integrate contact rolling neighbor system scenario
#   results/: processing io measurements model report
#   scheduler/: queue sweep pipeline cli (the queue knows job kinds by name; the impact kinds
#               register their runners from pipeline/)
# gravsweep_check_layering(<source dir>) stops with FATAL_ERROR naming each file and include
# that points the wrong way. Run as a script (cmake -DROOT=<dir> -P check_layering.cmake) from CTest.
set(GRAVSWEEP_FOLDER_ORDER
    "engine:core,geometry,integrate,contact,rolling,neighbor,system,scenario"
    "results:processing,io,measurements,model,report"
    "scheduler:queue,sweep,pipeline,serve,cli")

# Appends to `problems` (in the caller) each include in <root>/<lib>/ that reaches a later folder
# of the same library than the including file's.
function(gravsweep_check_folders root lib order)
  set(found "")
  list(LENGTH order n)
  math(EXPR last "${n} - 2")
  if(last GREATER_EQUAL 0)
    foreach(i RANGE ${last})
      list(GET order ${i} folder)
      math(EXPR next "${i} + 1")
      list(SUBLIST order ${next} -1 later)
      list(JOIN later "|" later)
      file(GLOB_RECURSE files "${root}/${lib}/${folder}/*.h" "${root}/${lib}/${folder}/*.cpp")
      foreach(f IN LISTS files)
        file(STRINGS "${f}" lines REGEX "^[ \t]*#[ \t]*include[ \t]*[\"<]${lib}/(${later})/")
        foreach(l IN LISTS lines)
          file(RELATIVE_PATH rel "${root}" "${f}")
          string(STRIP "${l}" l)
          string(APPEND found "\n  ${rel}: ${l} (${lib}/${folder}/ must not include ${lib}/{${later}}/)")
        endforeach()
      endforeach()
    endforeach()
  endif()
  set(problems "${problems}${found}" PARENT_SCOPE)
endfunction()

function(gravsweep_check_layering root)
  set(problems "")
  foreach(entry IN LISTS GRAVSWEEP_FOLDER_ORDER)
    string(FIND "${entry}" ":" colon)
    string(SUBSTRING "${entry}" 0 ${colon} lib)
    math(EXPR from "${colon} + 1")
    string(SUBSTRING "${entry}" ${from} -1 order)
    string(REPLACE "," ";" order "${order}")
    gravsweep_check_folders("${root}" "${lib}" "${order}")
  endforeach()
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
    message(FATAL_ERROR "layering: includes against the dependency direction (scheduler -> results -> spec -> engine; results -> db; inside each library the folder order above):${problems}")
  endif()
endfunction()

if(CMAKE_SCRIPT_MODE_FILE AND DEFINED ROOT)
  gravsweep_check_layering("${ROOT}")
  message(STATUS "layering: ok")
endif()
