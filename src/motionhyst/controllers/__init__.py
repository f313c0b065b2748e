"""Controllers of the loop (the paper's eq. (23) lead-lag with low-pass).
"""
