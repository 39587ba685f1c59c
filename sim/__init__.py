"""delve.sim"""
