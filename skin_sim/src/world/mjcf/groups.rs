//! Geom groups: what the sensors may see. The robot's geoms are in [`ROBOT_GROUP`], so skin and
//! LIDAR rays (which only test [`SENSED_GROUPS`]) never hit the robot itself.

/// Geom group of the floor and the scene's objects.
pub const OBJECT_GROUP: u8 = 0;
/// Geom group of the robot.
pub const ROBOT_GROUP: u8 = 1;
/// Geom group of the persons.
pub const PERSON_GROUP: u8 = 2;
/// Groups the skin's and the LIDAR's rays test (`mj_ray`'s geomgroup): objects and persons.
pub const SENSED_GROUPS: [u8; 6] = [1, 0, 1, 0, 0, 0];
