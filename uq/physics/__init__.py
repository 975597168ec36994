"""Pure lidar physics: numpy array functions and the compiled kernels."""
