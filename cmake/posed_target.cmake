# One place that decides how every posed target is compiled (DESIGN.md, Style).

set(POSED_SANITIZER_FLAGS "")
set(POSED_UBSAN_FLAGS "")
if(POSED_SANITIZE AND POSED_TSAN)
  message(FATAL_ERROR "POSED_SANITIZE and POSED_TSAN cannot be combined")
endif()
if(POSED_SANITIZE)
  # Eigen stops trusting malloc's 16-byte alignment under ASan (__SANITIZE_ADDRESS__) and frees
  # through its own aligned allocator, which reads 8 bytes before any matrix Ceres (built without
  # ASan) allocated: a heap-buffer-overflow in every Eigen object crossing that boundary. glibc's
  # and ASan's malloc both align to 16 on x86-64, so tell Eigen so, as the normal build does.
  set(POSED_SANITIZER_FLAGS -fsanitize=address -fno-omit-frame-pointer
                            -DEIGEN_MALLOC_ALREADY_ALIGNED=1)
  set(POSED_UBSAN_FLAGS -fsanitize=undefined -fno-sanitize-recover=undefined)
  # -O1 as the sanitizers' documentation recommends: reports stay readable and the build is ~15%
  # cheaper than -O2.
  set(CMAKE_C_FLAGS_RELWITHDEBINFO "-O1 -g1 -DNDEBUG")
  set(CMAKE_CXX_FLAGS_RELWITHDEBINFO "-O1 -g1 -DNDEBUG")
elseif(POSED_TSAN)
  set(POSED_SANITIZER_FLAGS -fsanitize=thread -fno-omit-frame-pointer)
endif()

# posed_target_defaults(<target> [UBSAN]): warnings, -Werror under POSED_WERROR, sanitizers.
# Under POSED_SANITIZE every target gets AddressSanitizer; UndefinedBehaviorSanitizer instruments
# the targets marked UBSAN (the layers that parse device bytes, files and config). It doubles the
# compile time of Eigen/Ceres-heavy code, where it would mostly check the libraries' templates, so
# the estimator, the tools and the test code are ASan-only; every executable links both runtimes.
function(posed_target_defaults target)
  cmake_parse_arguments(ARG "UBSAN" "" "" ${ARGN})
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wconversion -Wshadow
                                           -Wnon-virtual-dtor -Wpedantic)
  if(POSED_WERROR)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
  if(POSED_SANITIZER_FLAGS)
    # GCC's flow analysis under sanitizers reports libstdc++ internals (std::regex, std::function)
    # as maybe-uninitialized; the normal build keeps the warning.
    if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
      target_compile_options(${target} PRIVATE -Wno-maybe-uninitialized)
    endif()
    target_compile_options(${target} PRIVATE ${POSED_SANITIZER_FLAGS})
    target_link_options(${target} PRIVATE ${POSED_SANITIZER_FLAGS} ${POSED_UBSAN_FLAGS})
    if(ARG_UBSAN)
      target_compile_options(${target} PRIVATE ${POSED_UBSAN_FLAGS})
    endif()
  endif()
endfunction()

# posed_library(<name> [UBSAN] SOURCES ... [LIBS ...]): a static library of one layer.
function(posed_library name)
  cmake_parse_arguments(ARG "UBSAN" "" "SOURCES;LIBS" ${ARGN})
  add_library(${name} STATIC ${ARG_SOURCES})
  target_include_directories(${name} PUBLIC ${PROJECT_SOURCE_DIR})
  target_link_libraries(${name} PUBLIC ${ARG_LIBS})
  if(ARG_UBSAN)
    posed_target_defaults(${name} UBSAN)
  else()
    posed_target_defaults(${name})
  endif()
endfunction()

# posed_test(<name> LABEL unit|replay|integration|hw SOURCES ... [LIBS ...] [RESOURCE_LOCK lock]
#            [REAL_TIME]):
# one GoogleTest binary per area, each test discovered and labelled for ctest -L. Tests sharing a
# RESOURCE_LOCK (a fixed port, a machine-wide device) never run at the same time under ctest -j.
# REAL_TIME tests run a live posed against data paced in real time: they run alone (RUN_SERIAL),
# since on a 2-core machine a neighbouring test starves the live pipeline and its queues drop.
# Unit tests join the aggregate `sanitized_tests` that CI builds under ASan/UBSan, except those
# marked NOT_SANITIZED: numerical code on well-formed input (the simulator, trajectory
# evaluation, whole lidar drives), which takes minutes under ASan and parses no outside bytes.
function(posed_test name)
  cmake_parse_arguments(ARG "REAL_TIME;NOT_SANITIZED" "LABEL;TIMEOUT;RESOURCE_LOCK" "SOURCES;LIBS"
                        ${ARGN})
  if(NOT ARG_LABEL)
    message(FATAL_ERROR "posed_test(${name}) needs a LABEL")
  endif()
  if(NOT ARG_TIMEOUT)
    set(ARG_TIMEOUT 120)
  endif()
  # Sanitized builds run the same tests 3-15x slower (tools/sanitize-pipeline sets 10).
  math(EXPR ARG_TIMEOUT "${ARG_TIMEOUT} * ${POSED_TEST_TIMEOUT_SCALE}")
  add_executable(${name} ${ARG_SOURCES})
  # Test binaries compile as unity batches: each test file re-parses GoogleTest, Eigen and the
  # layer headers, which costs more than the test itself on a 2-core machine.
  set_target_properties(${name} PROPERTIES UNITY_BUILD ON UNITY_BUILD_BATCH_SIZE 6)
  # One aggregate per label (unit_tests, integration_tests, ...): CI's sanitizer builds compile
  # only the binaries the label they run needs.
  if(NOT TARGET ${ARG_LABEL}_tests)
    add_custom_target(${ARG_LABEL}_tests)
  endif()
  add_dependencies(${ARG_LABEL}_tests ${name})
  if(ARG_LABEL STREQUAL "unit" AND NOT ARG_NOT_SANITIZED)
    if(NOT TARGET sanitized_tests)
      add_custom_target(sanitized_tests)
    endif()
    add_dependencies(sanitized_tests ${name})
  endif()
  target_link_libraries(${name} PRIVATE ${ARG_LIBS} GTest::gtest GTest::gmock GTest::gtest_main)
  posed_target_defaults(${name})
  # Where the tests find the sources (config/, ../shared/realdata) and the built executables;
  # the environment variables of the same names override these.
  target_compile_definitions(${name} PRIVATE POSED_SOURCE_DIR_DEFAULT="${PROJECT_SOURCE_DIR}"
                                             POSED_BUILD_DIR_DEFAULT="${PROJECT_BINARY_DIR}")
  set(lock_property "")
  if(ARG_RESOURCE_LOCK)
    set(lock_property RESOURCE_LOCK ${ARG_RESOURCE_LOCK})
  endif()
  if(ARG_REAL_TIME)
    list(APPEND lock_property RUN_SERIAL TRUE)
  endif()
  gtest_discover_tests(${name}
    PROPERTIES LABELS ${ARG_LABEL} TIMEOUT ${ARG_TIMEOUT} ${lock_property}
               ENVIRONMENT "POSED_SOURCE_DIR=${PROJECT_SOURCE_DIR};POSED_BUILD_DIR=${PROJECT_BINARY_DIR}"
    DISCOVERY_TIMEOUT 60)
endfunction()
