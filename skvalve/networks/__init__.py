"""skvalve.networks"""
