"""Motion cueing: a vehicle's motion (specific force, angular velocity) turned into platform poses that a rider
perceives as that motion and that never leave the platform's workspace."""
