/// @file calibration_node_main.cpp
/// @brief Standalone calibration_node: loads online_stereo_calibration/CalibrationNodelet
/// in-process through nodelet::Loader (the same code path as in a manager).
#include <nodelet/loader.h>
#include <ros/ros.h>

int main(int argc, char** argv) {
  ros::init(argc, argv, "calibration_node");
  nodelet::Loader loader(false);
  nodelet::M_string remappings(ros::names::getRemappings());
  nodelet::V_string my_argv(argv + 1, argv + argc);
  if (!loader.load(ros::this_node::getName(), "online_stereo_calibration/CalibrationNodelet",
                   remappings, my_argv)) {
    ROS_FATAL("calibration_node: the nodelet did not load (see the errors above)");
    return 1;
  }
  ros::spin();
  return 0;
}
