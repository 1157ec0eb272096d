"""skvalve.valve"""
