#pragma once
// Internal to daemon/dds (and its tests): the C types idlc generates from daemon/dds/idl/ into
// the build tree. Nothing outside daemon/dds includes this; the daemon uses messages.hpp.

#include "builtin_interfaces.h"
#include "diagnostic_msgs.h"
#include "geometry_msgs.h"
#include "nav_msgs.h"
#include "posed_msgs.h"
#include "sensor_msgs.h"
#include "std_msgs.h"
#include "tf2_msgs.h"
