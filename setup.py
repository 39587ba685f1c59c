"""Package discovery for the one thing pyproject.toml cannot say statically: every
sub-package of the top-level folders, each installed under ``delve.`` (``executive/``
is ``delve.executive``). Trees and scenarios ship as package data of ``delve.trees``
and ``delve.scenarios``; ``delve/__init__.py`` finds them with importlib.resources."""
from setuptools import find_namespace_packages, setup

#: Top-level folders and the packages they are installed as.
FOLDERS = {"executive": "delve.executive", "skills": "delve.skills", "planners": "delve.planners",
           "sim": "delve.sim", "trees": "delve.trees", "scenarios": "delve.scenarios"}

packages = ["delve"]
for folder, package in FOLDERS.items():
    packages.append(package)
    packages += [f"{package}.{sub}" for sub in find_namespace_packages(folder, exclude=["*__pycache__*"])]

setup(packages=packages, package_dir={"delve": "delve", **{p: f for f, p in FOLDERS.items()}})
