"""delve.planners"""
