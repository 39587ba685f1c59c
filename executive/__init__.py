"""delve.executive"""
