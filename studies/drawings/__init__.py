"""Pictures of the drill itself: the string drawn to scale, its animation over the last blows, a built Exudyn
system drawn from its own graphics (items of one's own included), and Exudyn's solution file for its viewer."""
