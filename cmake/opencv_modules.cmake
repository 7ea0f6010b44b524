# OpenCV from Debian's per-module -dev packages (libopencv-core-dev, -imgproc-dev, ...).
# Debian ships OpenCVConfig.cmake and opencv4.pc only in the libopencv-dev meta package, which
# drags in every module (contrib, dnn, viz with VTK, ...): about 40 more packages than posed
# uses. So the modules are found one by one and exposed as imported targets `opencv::<module>`,
# with each module's own OpenCV dependencies attached.
set(_posed_opencv_modules core imgproc imgcodecs video calib3d features2d flann)
set(_posed_opencv_deps_imgproc core)
set(_posed_opencv_deps_imgcodecs core imgproc)
set(_posed_opencv_deps_flann core)
set(_posed_opencv_deps_features2d core imgproc flann)
set(_posed_opencv_deps_calib3d core imgproc features2d flann)
set(_posed_opencv_deps_video core imgproc calib3d)

find_path(POSED_OPENCV_INCLUDE_DIR opencv2/core.hpp PATH_SUFFIXES opencv4 REQUIRED)
foreach(module IN LISTS _posed_opencv_modules)
  find_library(POSED_OPENCV_${module}_LIBRARY opencv_${module} REQUIRED)
  if(NOT TARGET opencv::${module})
    add_library(opencv::${module} SHARED IMPORTED)
    set_target_properties(opencv::${module} PROPERTIES
      IMPORTED_LOCATION "${POSED_OPENCV_${module}_LIBRARY}"
      INTERFACE_INCLUDE_DIRECTORIES "${POSED_OPENCV_INCLUDE_DIR}")
  endif()
endforeach()
foreach(module IN LISTS _posed_opencv_modules)
  foreach(dep IN LISTS _posed_opencv_deps_${module})
    set_property(TARGET opencv::${module} APPEND PROPERTY INTERFACE_LINK_LIBRARIES opencv::${dep})
  endforeach()
endforeach()
