# ccache pays off on 2 cores: a rebuild after `git checkout` of unchanged TUs is free.
find_program(POSED_CCACHE ccache)
if(POSED_CCACHE)
  set(CMAKE_C_COMPILER_LAUNCHER "${POSED_CCACHE}")
  set(CMAKE_CXX_COMPILER_LAUNCHER "${POSED_CCACHE}")
endif()
