"""The shipped mission trees and subtrees (YAML), installed as package data."""
