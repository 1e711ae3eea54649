"""Electronic parts on a board: the component library and the part models of thesis section 7.2."""

from .library import MODELS, LibraryError, Package, find_package, read_package

__all__ = ["MODELS", "LibraryError", "Package", "find_package", "read_package"]
