# PCL from Debian's libpcl-dev, found library by library as cmake/opencv_modules.cmake finds
# OpenCV: PCLConfig.cmake looks for every optional dependency of every module (VTK, Qt, OpenNI,
# pcap, ...), which costs ~10 s of every configure and links VTK into whatever uses it. posed
# uses registration (GICP), filters (voxel grid) and kd-trees, in core/mapping only. Not pcl_io:
# it loads VTK, OpenNI and pcap at run time, which a daemon on a robot has no use for.
set(_posed_pcl_modules common octree kdtree search filters sample_consensus registration)
find_path(PCL_INCLUDE_DIRS pcl/point_types.h PATH_SUFFIXES pcl-1.13 REQUIRED)
set(POSED_PCL_LIBRARIES "")
foreach(module IN LISTS _posed_pcl_modules)
  find_library(POSED_PCL_${module}_LIBRARY pcl_${module} REQUIRED)
  list(APPEND POSED_PCL_LIBRARIES ${POSED_PCL_${module}_LIBRARY})
endforeach()
# pcl_io for the tests only: that PCL's own reader opens the map files posed writes.
find_library(POSED_PCL_io_LIBRARY pcl_io REQUIRED)
