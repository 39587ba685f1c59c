"""The shipped scenarios and their worlds (YAML, meshes), installed as package data."""
