"""IR layer: the one owner of llvmlite's IRBuilder, and the operation table."""
