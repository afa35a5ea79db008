// Placeholder: the kinematic driver lands in a follow-up commit.
