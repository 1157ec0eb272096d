"""skvalve.analytic"""
