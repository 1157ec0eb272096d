"""skvalve.multiscale"""
