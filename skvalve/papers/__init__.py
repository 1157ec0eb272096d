"""skvalve.papers"""
