# LLVM's lld links posed's ~50 executables (every test binary, posed, posectl) in about a quarter
# of the GNU linker's time (sim_tests: 0.75 s against 3.5 s), which adds up to minutes of a clean
# build on 2 cores, twice over in CI (release and sanitized). GCC 12 and clang both take
# -fuse-ld=lld; without lld (or with POSED_USE_LLD=OFF) the default linker is used.
option(POSED_USE_LLD "Link with lld when it is installed" ON)
if(POSED_USE_LLD)
  include(CheckLinkerFlag)
  check_linker_flag(CXX -fuse-ld=lld POSED_HAVE_LLD)
  if(POSED_HAVE_LLD)
    add_link_options(-fuse-ld=lld)
  endif()
endif()
