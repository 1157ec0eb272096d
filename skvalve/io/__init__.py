"""skvalve.io"""
