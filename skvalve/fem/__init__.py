"""skvalve.fem"""
