# ctest python.install: installs only the "python" component of BUILD_DIR into the scratch prefix
# SCRATCH and imports dmc from INSTALL_DIR there (not from the build tree) with interpreter PYTHON.
file(REMOVE_RECURSE "${SCRATCH}")
execute_process(COMMAND ${CMAKE_COMMAND} --install "${BUILD_DIR}" --component python
                        --prefix "${SCRATCH}"
                RESULT_VARIABLE install_result)
if(install_result)
  message(FATAL_ERROR "cmake --install of the python component failed")
endif()
set(site "${SCRATCH}/${INSTALL_DIR}")
execute_process(
  COMMAND ${CMAKE_COMMAND} -E env --unset=PYTHONPATH "PYTHONPATH=${site}" ${PYTHON} -c
          "import dmc, os; assert os.path.realpath(os.path.dirname(dmc.__file__)) == os.path.realpath('${site}/dmc'), dmc.__file__; f, t = dmc.synth('cloth', frames=2, resolution=100); assert dmc.metrics(f, f, t)['kg'] == 0.0; print('dmc', dmc.__version__, 'imported from', dmc.__file__)"
  WORKING_DIRECTORY "${SCRATCH}"  # not the build tree: `python -c` puts the cwd on sys.path
  RESULT_VARIABLE import_result)
file(REMOVE_RECURSE "${SCRATCH}")
if(import_result)
  message(FATAL_ERROR "importing the installed dmc module failed")
endif()
