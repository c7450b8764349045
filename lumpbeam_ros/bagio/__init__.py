"""rosbag2/MCAP reading and writing, and message <-> numpy conversion."""
