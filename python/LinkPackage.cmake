# Run after each build of tessera_python (cmake -P): links every file of the
# package python/tessera (SRC) into the build's package folder (DST), beside
# the extension, so that PYTHONPATH=BUILD/python imports the package with the
# sources' current text.
file(GLOB files RELATIVE ${SRC} ${SRC}/*.py ${SRC}/*.pyi ${SRC}/py.typed)
foreach(f ${files})
  file(CREATE_LINK ${SRC}/${f} ${DST}/${f} SYMBOLIC)
endforeach()
