! jprom's Fortran binding: Fortran 2008 interfaces to the whole C API of include/jprom.h
! through ISO_C_BINDING. Installed by packaging/install.sh (source, .mod files of the installing
! compiler, and libjprom_fortran.a with the wrappers' object code); or compile this file with
! your program and link -ljprom.
!
! Two modules:
!  * jprom_c: the raw bind(C) interface of every C function, the constants and the options
!    structs, exactly as in C. Handles are type(c_ptr); arrays are dimension(*) (column-major,
!    as Fortran stores them); sizes and indices are integer(c_size_t) and 0-BASED; strings are
!    NUL-terminated character(kind=c_char) arrays; functions returning `const char *` return a
!    type(c_ptr) (static or thread-local storage, never freed). A progress callback is a
!    bind(C) function passed as c_funloc(f) (see jprom_progress_fn in include/jprom.h).
!  * jprom (the module programs `use`; it re-exports the constants and the options types):
!    Fortran-friendly wrappers named jp_*. Each returns the status as a default integer
!    (JPROM_OK = 0) and, when the optional `message` is present, the error message on failure
!    (blank on success); outputs are written only on JPROM_OK. Strings are character(len=*)
!    (trailing blanks trimmed). Sizes come from the arrays passed (assumed shape).
!
! INDICES, once for the whole binding:
!  * in `jprom` every index is 1-BASED: DoFs, outputs, contacts, sweep points, corrections,
!    directions (1, 2, 3 = x, y, z) and the row indices and column pointers of sparse (CSC)
!    matrices (colptr(1) = 1, Harwell-Boeing style); the wrappers convert to the C API's 0-based
!    ones;
!  * harmonic numbers are not indices and are the same in both layers: h = 0 is the static
!    term, h = 1..H the harmonics; arrays over h are declared (0:H) (basis sizes, errors e_h);
!  * harmonic coefficients: coeffs(j, k + 1) is coefficient k of output j, k = 0 static,
!    k = 2h - 1 cos(h omega t), k = 2h sin(h omega t) (the C layout k * n_outputs + j, read
!    column-major without a copy);
!  * node ids of FE models are the FE code's own numbers in both layers;
!  * in `jprom_c` everything is 0-based as in C.
!
! Frequencies are angular (rad/s). Contact frames are frame(3, 3) with rows t1, t2, n
! (frame(i, :) is axis i) in the wrappers, the C row-major 9 values in jprom_c.
module jprom_c
  use, intrinsic :: iso_c_binding
  implicit none
  !> Status codes (jprom_status): fixed values.
  integer(c_int), parameter :: JPROM_OK = 0, JPROM_NULL_ARGUMENT = 1, JPROM_BAD_SIZE = 2, JPROM_INVALID_VALUE = 3, &
                               JPROM_SINGULAR_MATRIX = 4, JPROM_NO_CONVERGENCE = 5, JPROM_IO = 6, JPROM_PANIC = 7, &
                               JPROM_CANCELLED = 8, JPROM_INVALID_HANDLE = 9, JPROM_EIGEN = 10, JPROM_PARSE = 11, &
                               JPROM_CALLBACK_ERROR = 12
  !> Reduced-model kinds (jprom_rom_kind) and basis corrections (jprom_correction_kind).
  integer(c_int), parameter :: JPROM_ROM_FR = 0, JPROM_ROM_NLR = 1
  integer(c_int), parameter :: JPROM_CORRECTION_REGENERATED = 0, JPROM_CORRECTION_GAMMA_INCREASED = 1, &
                               JPROM_CORRECTION_REPLACED = 2
  !> Why the corrections of a self-correcting sweep ended (jprom_correction_end in C).
  integer(c_int), parameter :: JPROM_CORRECTIONS_WITHIN_THRESHOLD = 0, JPROM_CORRECTIONS_MAX_CORRECTIONS = 1, &
                               JPROM_CORRECTIONS_NO_PROGRESS = 2, JPROM_CORRECTIONS_CANCELLED = 3
  !> Where the JP prediction samples besides the stuck mode (jprom_slipping_samples, jprom_jp_options%slipping).
  integer(c_int), parameter :: JPROM_SLIPPING_NEVER = 0, JPROM_SLIPPING_AT_GROSS_SLIP = 1, JPROM_SLIPPING_ALWAYS = 2
  !> Why a sweep ended (jprom_sweep_end in C).
  integer(c_int), parameter :: JPROM_SWEEP_REACHED_END = 0, JPROM_SWEEP_STALLED = 1, JPROM_SWEEP_POINT_CAP = 2, &
                               JPROM_SWEEP_LEFT_BAND = 3, JPROM_SWEEP_CANCELLED = 4
  !> What a branch event is (jprom_event_kind in C).
  integer(c_int), parameter :: JPROM_EVENT_FOLD = 0, JPROM_EVENT_BRANCH_POINT = 1
  !> Documented caps (see include/jprom.h).
  integer(c_size_t), parameter :: JPROM_MAX_HARMONICS = 64, JPROM_MAX_NT = 65536, JPROM_MAX_SAMPLES = 10000, &
                                  JPROM_DENSE_MAX_DOF = 10000, JPROM_MAX_FORCE_HARMONIC = 1024
  !> Sizes of the options structs' first versions (struct_size of an older caller).
  integer(c_size_t), parameter :: JPROM_HBM_OPTIONS_V1_SIZE = 48, JPROM_SWEEP_OPTIONS_V1_SIZE = 56, &
                                  JPROM_JP_OPTIONS_V1_SIZE = 72, JPROM_JP_OPTIONS_V2_SIZE = 80

  !> Harmonic balance options. Fill with jprom_hbm_options_init(opts, c_sizeof(opts)).
  type, bind(C) :: jprom_hbm_options
    integer(c_size_t) :: struct_size
    integer(c_size_t) :: harmonics
    integer(c_size_t) :: nt
    real(c_double) :: residual_tolerance
    integer(c_size_t) :: max_iterations
    integer(c_int) :: condensed
  end type

  !> Sweep options (version 2, as include/jprom.h of jprom 0.2). Fill with
  !> jprom_sweep_options_init(opts, c_sizeof(opts)).
  type, bind(C) :: jprom_sweep_options
    integer(c_size_t) :: struct_size
    real(c_double) :: omega_start, omega_end
    real(c_double) :: initial_step, min_step, max_step
    integer(c_size_t) :: max_points
    real(c_double) :: max_omega_step, max_angle
  end type

  !> JP basis and self-correcting sweep options. Fill with jprom_jp_options_init(opts, c_sizeof(opts)).
  type, bind(C) :: jprom_jp_options
    integer(c_size_t) :: struct_size
    real(c_double) :: gamma
    integer(c_size_t) :: n_samples, extra_outside
    integer(c_int) :: static_correction
    real(c_double) :: threshold
    integer(c_size_t) :: max_corrections
    real(c_double) :: gamma_growth, max_gamma
    !> version 2 (0.3): a JPROM_SLIPPING_* value (default JPROM_SLIPPING_NEVER)
    integer(c_int) :: slipping
    !> version 3 (0.3): samples of a correction's prediction (default 10); screening of candidate bases and
    !> the linearised-error checks (nonzero: on, the defaults); the output locating a pass' resonance (0-based,
    !> default 0)
    integer(c_size_t) :: regeneration_samples
    integer(c_int) :: screen, verify
    integer(c_size_t) :: response_output
  end type

  interface
    ! ---- diagnostics, memory budget, errors, version ----
    integer(c_int) function jprom_live_handle_count(out) bind(C, name="jprom_live_handle_count")
      import :: c_int, c_size_t
      integer(c_size_t), intent(out) :: out
    end function
    integer(c_int) function jprom_set_memory_budget(bytes) bind(C, name="jprom_set_memory_budget")
      import :: c_int, c_size_t
      integer(c_size_t), value :: bytes
    end function
    integer(c_int) function jprom_memory_budget(out) bind(C, name="jprom_memory_budget")
      import :: c_int, c_size_t
      integer(c_size_t), intent(out) :: out
    end function
    integer(c_int) function jprom_set_time_budget(seconds) bind(C, name="jprom_set_time_budget")
      import :: c_int, c_double
      real(c_double), value :: seconds
    end function
    integer(c_int) function jprom_time_budget(out) bind(C, name="jprom_time_budget")
      import :: c_int, c_double
      real(c_double), intent(out) :: out
    end function
    integer(c_int) function jprom_set_reproducible(on) bind(C, name="jprom_set_reproducible")
      import :: c_int
      integer(c_int), value :: on
    end function
    integer(c_int) function jprom_reproducible(out) bind(C, name="jprom_reproducible")
      import :: c_int
      integer(c_int), intent(out) :: out
    end function
    function jprom_last_error_message() result(str) bind(C, name="jprom_last_error_message")
      import :: c_ptr
      type(c_ptr) :: str
    end function
    integer(c_int) function jprom_last_error_copy(buf, len, written) bind(C, name="jprom_last_error_copy")
      import :: c_int, c_size_t, c_char
      character(kind=c_char), dimension(*), intent(out) :: buf
      integer(c_size_t), value :: len
      integer(c_size_t), intent(out) :: written
    end function
    function jprom_status_name(status) result(str) bind(C, name="jprom_status_name")
      import :: c_ptr, c_int
      type(c_ptr) :: str
      integer(c_int), value :: status
    end function
    function jprom_version() result(str) bind(C, name="jprom_version")
      import :: c_ptr
      type(c_ptr) :: str
    end function

    ! ---- models ----
    integer(c_int) function jprom_model_new(n, mass, stiffness, out) bind(C, name="jprom_model_new")
      import :: c_int, c_size_t, c_double, c_ptr
      integer(c_size_t), value :: n
      real(c_double), dimension(*), intent(in) :: mass, stiffness
      type(c_ptr), intent(out) :: out
    end function
    integer(c_int) function jprom_model_new_csc(n, mass_colptr, mass_rowind, mass_values, stiffness_colptr, &
        stiffness_rowind, stiffness_values, out) bind(C, name="jprom_model_new_csc")
      import :: c_int, c_size_t, c_double, c_ptr
      integer(c_size_t), value :: n
      integer(c_size_t), dimension(*), intent(in) :: mass_colptr, mass_rowind, stiffness_colptr, stiffness_rowind
      real(c_double), dimension(*), intent(in) :: mass_values, stiffness_values
      type(c_ptr), intent(out) :: out
    end function
    integer(c_int) function jprom_model_clone(model, out) bind(C, name="jprom_model_clone")
      import :: c_int, c_ptr
      type(c_ptr), value :: model
      type(c_ptr), intent(out) :: out
    end function
    integer(c_int) function jprom_model_free(model) bind(C, name="jprom_model_free")
      import :: c_int, c_ptr
      type(c_ptr), value :: model
    end function
    integer(c_int) function jprom_model_n_dof(model, out) bind(C, name="jprom_model_n_dof")
      import :: c_int, c_size_t, c_ptr
      type(c_ptr), value :: model
      integer(c_size_t), intent(out) :: out
    end function
    integer(c_int) function jprom_model_n_contacts(model, out) bind(C, name="jprom_model_n_contacts")
      import :: c_int, c_size_t, c_ptr
      type(c_ptr), value :: model
      integer(c_size_t), intent(out) :: out
    end function
    integer(c_int) function jprom_model_n_outputs(model, out) bind(C, name="jprom_model_n_outputs")
      import :: c_int, c_size_t, c_ptr
      type(c_ptr), value :: model
      integer(c_size_t), intent(out) :: out
    end function
    integer(c_int) function jprom_model_set_rayleigh_damping(model, alpha, beta) &
        bind(C, name="jprom_model_set_rayleigh_damping")
      import :: c_int, c_double, c_ptr
      type(c_ptr), value :: model
      real(c_double), value :: alpha, beta
    end function
    integer(c_int) function jprom_model_set_modal_damping(model, zeta, omega) bind(C, name="jprom_model_set_modal_damping")
      import :: c_int, c_double, c_ptr
      type(c_ptr), value :: model
      real(c_double), value :: zeta, omega
    end function
    integer(c_int) function jprom_model_set_static_force(model, force, n) bind(C, name="jprom_model_set_static_force")
      import :: c_int, c_size_t, c_double, c_ptr
      type(c_ptr), value :: model
      real(c_double), dimension(*), intent(in) :: force
      integer(c_size_t), value :: n
    end function
    !> C accepts NULL for a zero part; here both parts are arrays of n values.
    integer(c_int) function jprom_model_set_harmonic_force(model, h, cos_part, sin_part, n) &
        bind(C, name="jprom_model_set_harmonic_force")
      import :: c_int, c_size_t, c_double, c_ptr
      type(c_ptr), value :: model
      integer(c_size_t), value :: h, n
      real(c_double), dimension(*), intent(in) :: cos_part, sin_part
    end function
    integer(c_int) function jprom_model_set_dynamic_scale(model, scale) bind(C, name="jprom_model_set_dynamic_scale")
      import :: c_int, c_ptr, c_double
      type(c_ptr), value :: model
      real(c_double), value :: scale
    end function
    integer(c_int) function jprom_model_set_excitation_level(model, alpha) bind(C, name="jprom_model_set_excitation_level")
      import :: c_int, c_ptr, c_double
      type(c_ptr), value :: model
      real(c_double), value :: alpha
    end function
    integer(c_int) function jprom_model_excitation_level(model, out) bind(C, name="jprom_model_excitation_level")
      import :: c_int, c_ptr, c_double
      type(c_ptr), value :: model
      real(c_double), intent(out) :: out
    end function
    !> dofs_b: c_loc of three DoFs of the other body, or c_null_ptr for a contact against ground.
    integer(c_int) function jprom_model_add_contact_3d(model, dofs_a, dofs_b, frame, kt1, kt2, kn, mu, n0) &
        bind(C, name="jprom_model_add_contact_3d")
      import :: c_int, c_size_t, c_double, c_ptr
      type(c_ptr), value :: model
      integer(c_size_t), dimension(*), intent(in) :: dofs_a
      type(c_ptr), value :: dofs_b
      real(c_double), dimension(*), intent(in) :: frame
      real(c_double), value :: kt1, kt2, kn, mu, n0
    end function
    !> dof_b: c_loc of the other DoF, or c_null_ptr for an element against ground.
    integer(c_int) function jprom_model_add_jenkins(model, dof_a, dof_b, kt, mu, normal_load) &
        bind(C, name="jprom_model_add_jenkins")
      import :: c_int, c_size_t, c_double, c_ptr
      type(c_ptr), value :: model
      integer(c_size_t), value :: dof_a
      type(c_ptr), value :: dof_b
      real(c_double), value :: kt, mu, normal_load
    end function
    !> dof_b: c_loc of the other DoF, or c_null_ptr for an element against ground.
    integer(c_int) function jprom_model_add_polynomial_spring(model, dof_a, dof_b, coefficients, n) &
        bind(C, name="jprom_model_add_polynomial_spring")
      import :: c_int, c_size_t, c_double, c_ptr
      type(c_ptr), value :: model
      integer(c_size_t), value :: dof_a
      type(c_ptr), value :: dof_b
      real(c_double), dimension(*), intent(in) :: coefficients
      integer(c_size_t), value :: n
    end function
    !> dof_b: c_loc of the other DoF, or c_null_ptr for an element against ground.
    integer(c_int) function jprom_model_add_unilateral_spring(model, dof_a, dof_b, kn, n0) &
        bind(C, name="jprom_model_add_unilateral_spring")
      import :: c_int, c_size_t, c_double, c_ptr
      type(c_ptr), value :: model
      integer(c_size_t), value :: dof_a
      type(c_ptr), value :: dof_b
      real(c_double), value :: kn, n0
    end function
    !> dofs_b: c_loc of two DoFs of the other body, or c_null_ptr for a contact against ground.
    integer(c_int) function jprom_model_add_friction_2d(model, dofs_a, dofs_b, frame, kt, kn, mu, n0) &
        bind(C, name="jprom_model_add_friction_2d")
      import :: c_int, c_size_t, c_double, c_ptr
      type(c_ptr), value :: model
      integer(c_size_t), dimension(*), intent(in) :: dofs_a
      type(c_ptr), value :: dofs_b
      real(c_double), dimension(*), intent(in) :: frame
      real(c_double), value :: kt, kn, mu, n0
    end function
    !> User-defined memoryless element: callback = c_funloc of a bind(C) function
    !>   integer(c_int32_t) function f(user_data, dim, w, force, jacobian) bind(C)
    !>     type(c_ptr), value :: user_data; integer(c_size_t), value :: dim
    !>     real(c_double), intent(in) :: w(dim); real(c_double) :: force(dim), jacobian(dim, dim)
    !> returning 0 on success (thread-safe; see include/jprom.h). dofs_b, frame: c_null_ptr for
    !> ground / the identity (frame: dim x dim row-major).
    integer(c_int) function jprom_model_add_element_callback(model, dim, dofs_a, dofs_b, frame, callback, user_data) &
        bind(C, name="jprom_model_add_element_callback")
      import :: c_int, c_size_t, c_ptr, c_funptr
      type(c_ptr), value :: model
      integer(c_size_t), value :: dim
      integer(c_size_t), dimension(*), intent(in) :: dofs_a
      type(c_ptr), value :: dofs_b
      type(c_ptr), value :: frame
      type(c_funptr), value :: callback
      type(c_ptr), value :: user_data
    end function
    integer(c_int) function jprom_model_set_output_dofs(model, dofs, n) bind(C, name="jprom_model_set_output_dofs")
      import :: c_int, c_size_t, c_ptr
      type(c_ptr), value :: model
      integer(c_size_t), dimension(*), intent(in) :: dofs
      integer(c_size_t), value :: n
    end function
    integer(c_int) function jprom_model_validate(model) bind(C, name="jprom_model_validate")
      import :: c_int, c_ptr
      type(c_ptr), value :: model
    end function
    integer(c_int) function jprom_model_save_json(model, path) bind(C, name="jprom_model_save_json")
      import :: c_int, c_ptr, c_char
      type(c_ptr), value :: model
      character(kind=c_char), dimension(*), intent(in) :: path
    end function
    integer(c_int) function jprom_model_load_json(path, out) bind(C, name="jprom_model_load_json")
      import :: c_int, c_ptr, c_char
      character(kind=c_char), dimension(*), intent(in) :: path
      type(c_ptr), intent(out) :: out
    end function

    ! ---- options ----
    !> The *_default functions write the first version of each struct only (struct_size = the
    !> V1 size), for callers of jprom 0.1; *_init writes every field of a struct of struct_size bytes.
    integer(c_int) function jprom_hbm_options_default(out) bind(C, name="jprom_hbm_options_default")
      import :: c_int, jprom_hbm_options
      type(jprom_hbm_options), intent(inout) :: out
    end function
    integer(c_int) function jprom_hbm_options_init(out, struct_size) bind(C, name="jprom_hbm_options_init")
      import :: c_int, c_size_t, jprom_hbm_options
      type(jprom_hbm_options), intent(out) :: out
      integer(c_size_t), value :: struct_size
    end function
    integer(c_int) function jprom_sweep_options_default(out) bind(C, name="jprom_sweep_options_default")
      import :: c_int, jprom_sweep_options
      type(jprom_sweep_options), intent(inout) :: out
    end function
    integer(c_int) function jprom_sweep_options_init(out, struct_size) bind(C, name="jprom_sweep_options_init")
      import :: c_int, c_size_t, jprom_sweep_options
      type(jprom_sweep_options), intent(out) :: out
      integer(c_size_t), value :: struct_size
    end function
    integer(c_int) function jprom_jp_options_default(out) bind(C, name="jprom_jp_options_default")
      import :: c_int, jprom_jp_options
      type(jprom_jp_options), intent(inout) :: out
    end function
    integer(c_int) function jprom_jp_options_init(out, struct_size) bind(C, name="jprom_jp_options_init")
      import :: c_int, c_size_t, jprom_jp_options
      type(jprom_jp_options), intent(out) :: out
      integer(c_size_t), value :: struct_size
    end function

    ! ---- full-order solutions and sweeps ----
    integer(c_int) function jprom_solve_point(model, omega, opts, out) bind(C, name="jprom_solve_point")
      import :: c_int, c_ptr, c_double, jprom_hbm_options
      type(c_ptr), value :: model
      real(c_double), value :: omega
      type(jprom_hbm_options), intent(in) :: opts
      type(c_ptr), intent(out) :: out
    end function
    integer(c_int) function jprom_sweep(model, opts, sweep_opts, callback, user_data, out) bind(C, name="jprom_sweep")
      import :: c_int, c_ptr, c_funptr, jprom_hbm_options, jprom_sweep_options
      type(c_ptr), value :: model
      type(jprom_hbm_options), intent(in) :: opts
      type(jprom_sweep_options), intent(in) :: sweep_opts
      type(c_funptr), value :: callback
      type(c_ptr), value :: user_data
      type(c_ptr), intent(out) :: out
    end function
    integer(c_int) function jprom_solve_point_from(model, omega, opts, guess, out) bind(C, name="jprom_solve_point_from")
      import :: c_int, c_ptr, c_double, jprom_hbm_options
      type(c_ptr), value :: model
      real(c_double), value :: omega
      type(jprom_hbm_options), intent(in) :: opts
      type(c_ptr), value :: guess
      type(c_ptr), intent(out) :: out
    end function
    integer(c_int) function jprom_sweep_from(model, opts, sweep_opts, start, callback, user_data, out) &
        bind(C, name="jprom_sweep_from")
      import :: c_int, c_ptr, c_funptr, jprom_hbm_options, jprom_sweep_options
      type(c_ptr), value :: model
      type(jprom_hbm_options), intent(in) :: opts
      type(jprom_sweep_options), intent(in) :: sweep_opts
      type(c_ptr), value :: start
      type(c_funptr), value :: callback
      type(c_ptr), value :: user_data
      type(c_ptr), intent(out) :: out
    end function
    integer(c_int) function jprom_solution_free(solution) bind(C, name="jprom_solution_free")
      import :: c_int, c_ptr
      type(c_ptr), value :: solution
    end function
    integer(c_int) function jprom_sweep_result_free(sweep) bind(C, name="jprom_sweep_result_free")
      import :: c_int, c_ptr
      type(c_ptr), value :: sweep
    end function
    !> Deprecated: use jprom_sweep_result_free.
    integer(c_int) function jprom_sweep_free(sweep) bind(C, name="jprom_sweep_free")
      import :: c_int, c_ptr
      type(c_ptr), value :: sweep
    end function
    integer(c_int) function jprom_sweep_result_n_points(sweep, out) bind(C, name="jprom_sweep_result_n_points")
      import :: c_int, c_size_t, c_ptr
      type(c_ptr), value :: sweep
      integer(c_size_t), intent(out) :: out
    end function
    !> Deprecated: use jprom_sweep_result_n_points.
    integer(c_int) function jprom_sweep_n_points(sweep, out) bind(C, name="jprom_sweep_n_points")
      import :: c_int, c_size_t, c_ptr
      type(c_ptr), value :: sweep
      integer(c_size_t), intent(out) :: out
    end function
    integer(c_int) function jprom_sweep_result_end_reason(sweep, out) bind(C, name="jprom_sweep_result_end_reason")
      import :: c_int, c_ptr
      type(c_ptr), value :: sweep
      integer(c_int), intent(out) :: out
    end function
    !> Deprecated: use jprom_sweep_result_end_reason.
    integer(c_int) function jprom_sweep_end_reason(sweep, out) bind(C, name="jprom_sweep_end_reason")
      import :: c_int, c_ptr
      type(c_ptr), value :: sweep
      integer(c_int), intent(out) :: out
    end function
    function jprom_sweep_end_name(reason) result(str) bind(C, name="jprom_sweep_end_name")
      import :: c_ptr, c_int
      type(c_ptr) :: str
      integer(c_int), value :: reason
    end function
    function jprom_correction_kind_name(kind) result(str) bind(C, name="jprom_correction_kind_name")
      import :: c_ptr, c_int
      type(c_ptr) :: str
      integer(c_int), value :: kind
    end function
    function jprom_correction_end_name(reason) result(str) bind(C, name="jprom_correction_end_name")
      import :: c_ptr, c_int
      type(c_ptr) :: str
      integer(c_int), value :: reason
    end function
    integer(c_int) function jprom_sweep_result_correction_end(sweep, reason, judged_error) &
        bind(C, name="jprom_sweep_result_correction_end")
      import :: c_int, c_ptr, c_double
      type(c_ptr), value :: sweep
      integer(c_int), intent(out) :: reason
      real(c_double), intent(out) :: judged_error
    end function
    integer(c_int) function jprom_sweep_result_correction_swept(sweep, i, out) &
        bind(C, name="jprom_sweep_result_correction_swept")
      import :: c_int, c_ptr, c_size_t
      type(c_ptr), value :: sweep
      integer(c_size_t), value :: i
      integer(c_int), intent(out) :: out
    end function
    integer(c_int) function jprom_sweep_result_static_error(sweep, out) &
        bind(C, name="jprom_sweep_result_static_error")
      import :: c_int, c_ptr, c_double
      type(c_ptr), value :: sweep
      real(c_double), intent(out) :: out
    end function
    integer(c_int) function jprom_sweep_result_trusted(sweep, out) bind(C, name="jprom_sweep_result_trusted")
      import :: c_int, c_ptr
      type(c_ptr), value :: sweep
      integer(c_int), intent(out) :: out
    end function
    integer(c_int) function jprom_sweep_result_trust_reason_copy(sweep, buf, len, written) &
        bind(C, name="jprom_sweep_result_trust_reason_copy")
      import :: c_int, c_size_t, c_ptr, c_char
      type(c_ptr), value :: sweep
      character(kind=c_char), dimension(*), intent(out) :: buf
      integer(c_size_t), value :: len
      integer(c_size_t), intent(out) :: written
    end function
    integer(c_int) function jprom_sweep_result_point_judged_error(sweep, i, out) &
        bind(C, name="jprom_sweep_result_point_judged_error")
      import :: c_int, c_ptr, c_size_t, c_double
      type(c_ptr), value :: sweep
      integer(c_size_t), value :: i
      real(c_double), intent(out) :: out
    end function
    integer(c_int) function jprom_sweep_result_reached_end(sweep, out) bind(C, name="jprom_sweep_result_reached_end")
      import :: c_int, c_ptr
      type(c_ptr), value :: sweep
      integer(c_int), intent(out) :: out
    end function
    !> Deprecated: use jprom_sweep_result_reached_end (jprom_sweep_reached_end is jprom_sweep_reached_end_fn here:
    !> Fortran names ignore case, and JPROM_SWEEP_REACHED_END is the end reason).
    integer(c_int) function jprom_sweep_reached_end_fn(sweep, out) bind(C, name="jprom_sweep_reached_end")
      import :: c_int, c_ptr
      type(c_ptr), value :: sweep
      integer(c_int), intent(out) :: out
    end function
    integer(c_int) function jprom_sweep_result_failure_copy(sweep, buf, len, written) &
        bind(C, name="jprom_sweep_result_failure_copy")
      import :: c_int, c_size_t, c_ptr, c_char
      type(c_ptr), value :: sweep
      character(kind=c_char), dimension(*), intent(out) :: buf
      integer(c_size_t), value :: len
      integer(c_size_t), intent(out) :: written
    end function
    integer(c_int) function jprom_sweep_result_n_events(sweep, out) bind(C, name="jprom_sweep_result_n_events")
      import :: c_int, c_size_t, c_ptr
      type(c_ptr), value :: sweep
      integer(c_size_t), intent(out) :: out
    end function
    integer(c_int) function jprom_sweep_result_event(sweep, i, kind, omega, omega_tolerance, after_point, amplitude) &
        bind(C, name="jprom_sweep_result_event")
      import :: c_int, c_size_t, c_ptr, c_double
      type(c_ptr), value :: sweep
      integer(c_size_t), value :: i
      integer(c_int), intent(out) :: kind
      real(c_double), intent(out) :: omega, omega_tolerance
      integer(c_size_t), intent(out) :: after_point
      real(c_double), intent(out) :: amplitude
    end function
    function jprom_event_kind_name(kind) result(str) bind(C, name="jprom_event_kind_name")
      import :: c_ptr, c_int
      type(c_ptr) :: str
      integer(c_int), value :: kind
    end function
    integer(c_int) function jprom_sweep_result_n_gaps(sweep, out) bind(C, name="jprom_sweep_result_n_gaps")
      import :: c_int, c_size_t, c_ptr
      type(c_ptr), value :: sweep
      integer(c_size_t), intent(out) :: out
    end function
    integer(c_int) function jprom_sweep_result_gap(sweep, i, from, to) bind(C, name="jprom_sweep_result_gap")
      import :: c_int, c_size_t, c_ptr, c_double
      type(c_ptr), value :: sweep
      integer(c_size_t), value :: i
      real(c_double), intent(out) :: from, to
    end function
    integer(c_int) function jprom_sweep_result_gap_reason_copy(sweep, i, buf, len, written) &
        bind(C, name="jprom_sweep_result_gap_reason_copy")
      import :: c_int, c_size_t, c_ptr, c_char
      type(c_ptr), value :: sweep
      integer(c_size_t), value :: i
      character(kind=c_char), dimension(*), intent(out) :: buf
      integer(c_size_t), value :: len
      integer(c_size_t), intent(out) :: written
    end function
    !> Deprecated: use jprom_sweep_result_failure_copy.
    integer(c_int) function jprom_sweep_failure_copy(sweep, buf, len, written) bind(C, name="jprom_sweep_failure_copy")
      import :: c_int, c_size_t, c_ptr, c_char
      type(c_ptr), value :: sweep
      character(kind=c_char), dimension(*), intent(out) :: buf
      integer(c_size_t), value :: len
      integer(c_size_t), intent(out) :: written
    end function
    integer(c_int) function jprom_sweep_result_point(sweep, i, out) bind(C, name="jprom_sweep_result_point")
      import :: c_int, c_size_t, c_ptr
      type(c_ptr), value :: sweep
      integer(c_size_t), value :: i
      type(c_ptr), intent(out) :: out
    end function
    !> Deprecated: use jprom_sweep_result_point.
    integer(c_int) function jprom_sweep_point(sweep, i, out) bind(C, name="jprom_sweep_point")
      import :: c_int, c_size_t, c_ptr
      type(c_ptr), value :: sweep
      integer(c_size_t), value :: i
      type(c_ptr), intent(out) :: out
    end function
    integer(c_int) function jprom_sweep_result_point_omega(sweep, i, out) bind(C, name="jprom_sweep_result_point_omega")
      import :: c_int, c_size_t, c_double, c_ptr
      type(c_ptr), value :: sweep
      integer(c_size_t), value :: i
      real(c_double), intent(out) :: out
    end function
    !> Deprecated: use jprom_sweep_result_point_omega.
    integer(c_int) function jprom_sweep_point_omega(sweep, i, out) bind(C, name="jprom_sweep_point_omega")
      import :: c_int, c_size_t, c_double, c_ptr
      type(c_ptr), value :: sweep
      integer(c_size_t), value :: i
      real(c_double), intent(out) :: out
    end function
    integer(c_int) function jprom_sweep_result_point_amplitude(sweep, i, h, j, out) &
        bind(C, name="jprom_sweep_result_point_amplitude")
      import :: c_int, c_size_t, c_double, c_ptr
      type(c_ptr), value :: sweep
      integer(c_size_t), value :: i, h, j
      real(c_double), intent(out) :: out
    end function
    !> Deprecated: use jprom_sweep_result_point_amplitude.
    integer(c_int) function jprom_sweep_point_amplitude(sweep, i, h, j, out) bind(C, name="jprom_sweep_point_amplitude")
      import :: c_int, c_size_t, c_double, c_ptr
      type(c_ptr), value :: sweep
      integer(c_size_t), value :: i, h, j
      real(c_double), intent(out) :: out
    end function
    integer(c_int) function jprom_sweep_result_point_output_coeffs(sweep, i, buf, len) &
        bind(C, name="jprom_sweep_result_point_output_coeffs")
      import :: c_int, c_size_t, c_double, c_ptr
      type(c_ptr), value :: sweep
      integer(c_size_t), value :: i, len
      real(c_double), dimension(*), intent(out) :: buf
    end function
    !> Deprecated: use jprom_sweep_result_point_output_coeffs.
    integer(c_int) function jprom_sweep_point_output_coeffs(sweep, i, buf, len) &
        bind(C, name="jprom_sweep_point_output_coeffs")
      import :: c_int, c_size_t, c_double, c_ptr
      type(c_ptr), value :: sweep
      integer(c_size_t), value :: i, len
      real(c_double), dimension(*), intent(out) :: buf
    end function
    integer(c_int) function jprom_sweep_result_point_dissipated_energy(sweep, i, buf, len) &
        bind(C, name="jprom_sweep_result_point_dissipated_energy")
      import :: c_int, c_size_t, c_double, c_ptr
      type(c_ptr), value :: sweep
      integer(c_size_t), value :: i, len
      real(c_double), dimension(*), intent(out) :: buf
    end function
    !> Deprecated: use jprom_sweep_result_point_dissipated_energy.
    integer(c_int) function jprom_sweep_point_dissipated_energy(sweep, i, buf, len) &
        bind(C, name="jprom_sweep_point_dissipated_energy")
      import :: c_int, c_size_t, c_double, c_ptr
      type(c_ptr), value :: sweep
      integer(c_size_t), value :: i, len
      real(c_double), dimension(*), intent(out) :: buf
    end function
    integer(c_int) function jprom_sweep_result_point_convergence(sweep, i, iterations, residual) &
        bind(C, name="jprom_sweep_result_point_convergence")
      import :: c_int, c_size_t, c_double, c_ptr
      type(c_ptr), value :: sweep
      integer(c_size_t), value :: i
      integer(c_size_t), intent(out) :: iterations
      real(c_double), intent(out) :: residual
    end function
    !> Deprecated: use jprom_sweep_result_point_convergence.
    integer(c_int) function jprom_sweep_point_convergence(sweep, i, iterations, residual) &
        bind(C, name="jprom_sweep_point_convergence")
      import :: c_int, c_size_t, c_double, c_ptr
      type(c_ptr), value :: sweep
      integer(c_size_t), value :: i
      integer(c_size_t), intent(out) :: iterations
      real(c_double), intent(out) :: residual
    end function
    integer(c_int) function jprom_sweep_result_save_json(sweep, path) bind(C, name="jprom_sweep_result_save_json")
      import :: c_int, c_ptr, c_char
      type(c_ptr), value :: sweep
      character(kind=c_char), dimension(*), intent(in) :: path
    end function
    !> Deprecated: use jprom_sweep_result_save_json.
    integer(c_int) function jprom_sweep_save_json(sweep, path) bind(C, name="jprom_sweep_save_json")
      import :: c_int, c_ptr, c_char
      type(c_ptr), value :: sweep
      character(kind=c_char), dimension(*), intent(in) :: path
    end function
    integer(c_int) function jprom_sweep_result_load_json(path, out) bind(C, name="jprom_sweep_result_load_json")
      import :: c_int, c_ptr, c_char
      character(kind=c_char), dimension(*), intent(in) :: path
      type(c_ptr), intent(out) :: out
    end function
    !> Deprecated: use jprom_sweep_result_load_json.
    integer(c_int) function jprom_sweep_load_json(path, out) bind(C, name="jprom_sweep_load_json")
      import :: c_int, c_ptr, c_char
      character(kind=c_char), dimension(*), intent(in) :: path
      type(c_ptr), intent(out) :: out
    end function
    integer(c_int) function jprom_solution_omega(solution, out) bind(C, name="jprom_solution_omega")
      import :: c_int, c_ptr, c_double
      type(c_ptr), value :: solution
      real(c_double), intent(out) :: out
    end function
    integer(c_int) function jprom_solution_sizes(solution, harmonics, n_outputs, n_contacts) &
        bind(C, name="jprom_solution_sizes")
      import :: c_int, c_ptr, c_size_t
      type(c_ptr), value :: solution
      integer(c_size_t), intent(out) :: harmonics, n_outputs, n_contacts
    end function
    integer(c_int) function jprom_solution_output_coeffs(solution, buf, len) bind(C, name="jprom_solution_output_coeffs")
      import :: c_int, c_ptr, c_size_t, c_double
      type(c_ptr), value :: solution
      real(c_double), dimension(*), intent(out) :: buf
      integer(c_size_t), value :: len
    end function
    integer(c_int) function jprom_solution_amplitude(solution, h, j, out) bind(C, name="jprom_solution_amplitude")
      import :: c_int, c_ptr, c_size_t, c_double
      type(c_ptr), value :: solution
      integer(c_size_t), value :: h, j
      real(c_double), intent(out) :: out
    end function
    integer(c_int) function jprom_solution_convergence(solution, iterations, residual) &
        bind(C, name="jprom_solution_convergence")
      import :: c_int, c_ptr, c_size_t, c_double
      type(c_ptr), value :: solution
      integer(c_size_t), intent(out) :: iterations
      real(c_double), intent(out) :: residual
    end function
    integer(c_int) function jprom_solution_dissipated_energy(solution, buf, len) &
        bind(C, name="jprom_solution_dissipated_energy")
      import :: c_int, c_ptr, c_size_t, c_double
      type(c_ptr), value :: solution
      real(c_double), dimension(*), intent(out) :: buf
      integer(c_size_t), value :: len
    end function
    integer(c_int) function jprom_solution_n_samples(solution, out) bind(C, name="jprom_solution_n_samples")
      import :: c_int, c_ptr, c_size_t
      type(c_ptr), value :: solution
      integer(c_size_t), intent(out) :: out
    end function
    integer(c_int) function jprom_solution_contact_states(solution, contact, buf, len) &
        bind(C, name="jprom_solution_contact_states")
      import :: c_int, c_ptr, c_size_t, c_int8_t
      type(c_ptr), value :: solution
      integer(c_size_t), value :: contact, len
      integer(c_int8_t), dimension(*), intent(out) :: buf
    end function
    integer(c_int) function jprom_solution_save_json(solution, path) bind(C, name="jprom_solution_save_json")
      import :: c_int, c_ptr, c_char
      type(c_ptr), value :: solution
      character(kind=c_char), dimension(*), intent(in) :: path
    end function
    integer(c_int) function jprom_solution_load_json(path, out) bind(C, name="jprom_solution_load_json")
      import :: c_int, c_ptr, c_char
      character(kind=c_char), dimension(*), intent(in) :: path
      type(c_ptr), intent(out) :: out
    end function

    ! ---- JP reduction ----
    !> Deprecated: use jprom_basis_predict_opts.
    integer(c_int) function jprom_basis_predict(model, opts, omega_start, omega_end, gamma, n_samples, out) &
        bind(C, name="jprom_basis_predict")
      import :: c_int, c_double, c_size_t, c_ptr, jprom_hbm_options
      type(c_ptr), value :: model
      type(jprom_hbm_options), intent(in) :: opts
      real(c_double), value :: omega_start, omega_end, gamma
      integer(c_size_t), value :: n_samples
      type(c_ptr), intent(out) :: out
    end function
    integer(c_int) function jprom_basis_predict_opts(model, opts, jp_opts, omega_start, omega_end, out) &
        bind(C, name="jprom_basis_predict_opts")
      import :: c_int, c_double, c_ptr, jprom_hbm_options, jprom_jp_options
      type(c_ptr), value :: model
      type(jprom_hbm_options), intent(in) :: opts
      type(jprom_jp_options), intent(in) :: jp_opts
      real(c_double), value :: omega_start, omega_end
      type(c_ptr), intent(out) :: out
    end function
    integer(c_int) function jprom_basis_from_solution(model, solution, opts, jp_opts, omega_start, omega_end, out) &
        bind(C, name="jprom_basis_from_solution")
      import :: c_int, c_double, c_ptr, jprom_hbm_options, jprom_jp_options
      type(c_ptr), value :: model, solution
      type(jprom_hbm_options), intent(in) :: opts
      type(jprom_jp_options), intent(in) :: jp_opts
      real(c_double), value :: omega_start, omega_end
      type(c_ptr), intent(out) :: out
    end function
    integer(c_int) function jprom_basis_free(basis) bind(C, name="jprom_basis_free")
      import :: c_int, c_ptr
      type(c_ptr), value :: basis
    end function
    integer(c_int) function jprom_basis_sizes(basis, buf, len, harmonics) bind(C, name="jprom_basis_sizes")
      import :: c_int, c_size_t, c_ptr
      type(c_ptr), value :: basis
      integer(c_size_t), dimension(*), intent(out) :: buf
      integer(c_size_t), value :: len
      integer(c_size_t), intent(out) :: harmonics
    end function
    integer(c_int) function jprom_basis_save_json(basis, path) bind(C, name="jprom_basis_save_json")
      import :: c_int, c_ptr, c_char
      type(c_ptr), value :: basis
      character(kind=c_char), dimension(*), intent(in) :: path
    end function
    integer(c_int) function jprom_basis_load_json(path, out) bind(C, name="jprom_basis_load_json")
      import :: c_int, c_ptr, c_char
      character(kind=c_char), dimension(*), intent(in) :: path
      type(c_ptr), intent(out) :: out
    end function
    integer(c_int) function jprom_rom_sweep(model, basis, kind, opts, sweep_opts, callback, user_data, out) &
        bind(C, name="jprom_rom_sweep")
      import :: c_int, c_ptr, c_funptr, jprom_hbm_options, jprom_sweep_options
      type(c_ptr), value :: model, basis
      integer(c_int), value :: kind
      type(jprom_hbm_options), intent(in) :: opts
      type(jprom_sweep_options), intent(in) :: sweep_opts
      type(c_funptr), value :: callback
      type(c_ptr), value :: user_data
      type(c_ptr), intent(out) :: out
    end function
    integer(c_int) function jprom_rom_sweep_adaptive(model, kind, opts, sweep_opts, jp_opts, callback, user_data, out, &
        basis_out) bind(C, name="jprom_rom_sweep_adaptive")
      import :: c_int, c_ptr, c_funptr, jprom_hbm_options, jprom_sweep_options, jprom_jp_options
      type(c_ptr), value :: model
      integer(c_int), value :: kind
      type(jprom_hbm_options), intent(in) :: opts
      type(jprom_sweep_options), intent(in) :: sweep_opts
      type(jprom_jp_options), intent(in) :: jp_opts
      type(c_funptr), value :: callback
      type(c_ptr), value :: user_data
      type(c_ptr), intent(out) :: out, basis_out
    end function
    integer(c_int) function jprom_sweep_result_point_predicted_error(sweep, i, h, out) &
        bind(C, name="jprom_sweep_result_point_predicted_error")
      import :: c_int, c_size_t, c_double, c_ptr
      type(c_ptr), value :: sweep
      integer(c_size_t), value :: i, h
      real(c_double), intent(out) :: out
    end function
    !> Deprecated: use jprom_sweep_result_point_predicted_error.
    integer(c_int) function jprom_sweep_point_predicted_error(sweep, i, h, out) &
        bind(C, name="jprom_sweep_point_predicted_error")
      import :: c_int, c_size_t, c_double, c_ptr
      type(c_ptr), value :: sweep
      integer(c_size_t), value :: i, h
      real(c_double), intent(out) :: out
    end function
    integer(c_int) function jprom_sweep_result_n_corrections(sweep, out) bind(C, name="jprom_sweep_result_n_corrections")
      import :: c_int, c_size_t, c_ptr
      type(c_ptr), value :: sweep
      integer(c_size_t), intent(out) :: out
    end function
    !> Deprecated: use jprom_sweep_result_n_corrections.
    integer(c_int) function jprom_sweep_n_corrections(sweep, out) bind(C, name="jprom_sweep_n_corrections")
      import :: c_int, c_size_t, c_ptr
      type(c_ptr), value :: sweep
      integer(c_size_t), intent(out) :: out
    end function
    integer(c_int) function jprom_sweep_result_correction(sweep, i, kind, value, worst_before, worst_after, sizes, len) &
        bind(C, name="jprom_sweep_result_correction")
      import :: c_int, c_size_t, c_double, c_ptr
      type(c_ptr), value :: sweep
      integer(c_size_t), value :: i, len
      integer(c_int), intent(out) :: kind
      real(c_double), intent(out) :: value, worst_before, worst_after
      integer(c_size_t), dimension(*), intent(out) :: sizes
    end function
    !> Deprecated: use jprom_sweep_result_correction.
    integer(c_int) function jprom_sweep_correction(sweep, i, kind, value, worst_before, worst_after, sizes, len) &
        bind(C, name="jprom_sweep_correction")
      import :: c_int, c_size_t, c_double, c_ptr
      type(c_ptr), value :: sweep
      integer(c_size_t), value :: i, len
      integer(c_int), intent(out) :: kind
      real(c_double), intent(out) :: value, worst_before, worst_after
      integer(c_size_t), dimension(*), intent(out) :: sizes
    end function
    integer(c_int) function jprom_rom_actual_error(model, basis, kind, opts, rom_solution, full_solution, buf, len) &
        bind(C, name="jprom_rom_actual_error")
      import :: c_int, c_size_t, c_double, c_ptr, jprom_hbm_options
      type(c_ptr), value :: model, basis
      integer(c_int), value :: kind
      type(jprom_hbm_options), intent(in) :: opts
      type(c_ptr), value :: rom_solution, full_solution
      real(c_double), dimension(*), intent(out) :: buf
      integer(c_size_t), value :: len
    end function

    ! ---- FE models: from sparse K, M and nodes (or CalculiX output) to a jprom model by Craig-Bampton ----
    integer(c_int) function jprom_fe_model_new_csc(n, stiffness_colptr, stiffness_rowind, stiffness_values, mass_colptr, &
        mass_rowind, mass_values, n_nodes, node_ids, node_rows, out) bind(C, name="jprom_fe_model_new_csc")
      import :: c_int, c_size_t, c_double, c_int64_t, c_ptr
      integer(c_size_t), value :: n, n_nodes
      integer(c_size_t), dimension(*), intent(in) :: stiffness_colptr, stiffness_rowind, mass_colptr, mass_rowind
      real(c_double), dimension(*), intent(in) :: stiffness_values, mass_values
      integer(c_int64_t), dimension(*), intent(in) :: node_ids, node_rows
      type(c_ptr), intent(out) :: out
    end function
    integer(c_int) function jprom_fe_model_load_calculix(inp, fe) bind(C, name="jprom_fe_model_load_calculix")
      import :: c_int, c_char, c_ptr
      character(kind=c_char), dimension(*), intent(in) :: inp
      type(c_ptr), intent(out) :: fe
    end function
    integer(c_int) function jprom_fe_model_free(fe) bind(C, name="jprom_fe_model_free")
      import :: c_int, c_ptr
      type(c_ptr), value :: fe
    end function
    integer(c_int) function jprom_fe_model_n_dof(fe, out) bind(C, name="jprom_fe_model_n_dof")
      import :: c_int, c_ptr, c_size_t
      type(c_ptr), value :: fe
      integer(c_size_t), intent(out) :: out
    end function
    integer(c_int) function jprom_fe_model_node_set(fe, name, ids, len, count) bind(C, name="jprom_fe_model_node_set")
      import :: c_int, c_char, c_ptr, c_size_t, c_int64_t
      type(c_ptr), value :: fe
      character(kind=c_char), dimension(*), intent(in) :: name
      integer(c_int64_t), dimension(*), intent(out) :: ids
      integer(c_size_t), value :: len
      integer(c_size_t), intent(out) :: count
    end function
    integer(c_int) function jprom_fe_model_add_contact(fe, node, frame, kt1, kt2, kn, mu, n0) &
        bind(C, name="jprom_fe_model_add_contact")
      import :: c_int, c_ptr, c_int64_t, c_double
      type(c_ptr), value :: fe
      integer(c_int64_t), value :: node
      real(c_double), dimension(*), intent(in) :: frame
      real(c_double), value :: kt1, kt2, kn, mu, n0
    end function
    !> Deprecated: use jprom_fe_model_add_contact.
    integer(c_int) function jprom_fe_add_contact(fe, node, frame, kt1, kt2, kn, mu, n0) bind(C, name="jprom_fe_add_contact")
      import :: c_int, c_ptr, c_int64_t, c_double
      type(c_ptr), value :: fe
      integer(c_int64_t), value :: node
      real(c_double), dimension(*), intent(in) :: frame
      real(c_double), value :: kt1, kt2, kn, mu, n0
    end function
    integer(c_int) function jprom_fe_model_add_force(fe, node, harmonic, force) bind(C, name="jprom_fe_model_add_force")
      import :: c_int, c_ptr, c_int64_t, c_size_t, c_double
      type(c_ptr), value :: fe
      integer(c_int64_t), value :: node
      integer(c_size_t), value :: harmonic
      real(c_double), dimension(*), intent(in) :: force
    end function
    !> Deprecated: use jprom_fe_model_add_force.
    integer(c_int) function jprom_fe_add_force(fe, node, harmonic, force) bind(C, name="jprom_fe_add_force")
      import :: c_int, c_ptr, c_int64_t, c_size_t, c_double
      type(c_ptr), value :: fe
      integer(c_int64_t), value :: node
      integer(c_size_t), value :: harmonic
      real(c_double), dimension(*), intent(in) :: force
    end function
    integer(c_int) function jprom_fe_model_add_output(fe, node, direction) bind(C, name="jprom_fe_model_add_output")
      import :: c_int, c_ptr, c_int64_t, c_size_t
      type(c_ptr), value :: fe
      integer(c_int64_t), value :: node
      integer(c_size_t), value :: direction
    end function
    !> Deprecated: use jprom_fe_model_add_output.
    integer(c_int) function jprom_fe_add_output(fe, node, direction) bind(C, name="jprom_fe_add_output")
      import :: c_int, c_ptr, c_int64_t, c_size_t
      type(c_ptr), value :: fe
      integer(c_int64_t), value :: node
      integer(c_size_t), value :: direction
    end function
    integer(c_int) function jprom_fe_model_keep_node(fe, node) bind(C, name="jprom_fe_model_keep_node")
      import :: c_int, c_ptr, c_int64_t
      type(c_ptr), value :: fe
      integer(c_int64_t), value :: node
    end function
    !> Deprecated: use jprom_fe_model_keep_node.
    integer(c_int) function jprom_fe_keep_node(fe, node) bind(C, name="jprom_fe_keep_node")
      import :: c_int, c_ptr, c_int64_t
      type(c_ptr), value :: fe
      integer(c_int64_t), value :: node
    end function
    integer(c_int) function jprom_fe_model_reduce(fe, cb_modes, model) bind(C, name="jprom_fe_model_reduce")
      import :: c_int, c_ptr, c_size_t
      type(c_ptr), value :: fe
      integer(c_size_t), value :: cb_modes
      type(c_ptr), intent(out) :: model
    end function
    integer(c_int) function jprom_fe_model_unreduced(fe, model) bind(C, name="jprom_fe_model_unreduced")
      import :: c_int, c_ptr
      type(c_ptr), value :: fe
      type(c_ptr), intent(out) :: model
    end function
    !> Deprecated: use jprom_fe_model_reduce.
    integer(c_int) function jprom_fe_reduce(fe, cb_modes, model) bind(C, name="jprom_fe_reduce")
      import :: c_int, c_ptr, c_size_t
      type(c_ptr), value :: fe
      integer(c_size_t), value :: cb_modes
      type(c_ptr), intent(out) :: model
    end function
    ! damping forms and natural modes
    integer(c_int) function jprom_model_set_damping_matrix(model, c, n) bind(C, name="jprom_model_set_damping_matrix")
      import :: c_int, c_ptr, c_size_t
      type(c_ptr), value :: model
      type(c_ptr), value :: c
      integer(c_size_t), value :: n
    end function
    integer(c_int) function jprom_model_set_modal_damping_ratios(model, ratios, n_ratios, others) &
        bind(C, name="jprom_model_set_modal_damping_ratios")
      import :: c_int, c_ptr, c_size_t, c_double
      type(c_ptr), value :: model
      real(c_double), dimension(*), intent(in) :: ratios
      integer(c_size_t), value :: n_ratios
      real(c_double), value :: others
    end function
    integer(c_int) function jprom_model_set_loss_factor(model, eta) bind(C, name="jprom_model_set_loss_factor")
      import :: c_int, c_ptr, c_double
      type(c_ptr), value :: model
      real(c_double), value :: eta
    end function
    integer(c_int) function jprom_model_modes(model, stuck, frequency_hz, modal_force, len, count) &
        bind(C, name="jprom_model_modes")
      import :: c_int, c_ptr, c_size_t, c_double, c_int32_t
      type(c_ptr), value :: model
      integer(c_int32_t), value :: stuck
      real(c_double), dimension(*), intent(out) :: frequency_hz
      type(c_ptr), value :: modal_force
      integer(c_size_t), value :: len
      integer(c_size_t), intent(out) :: count
    end function
    integer(c_int) function jprom_fe_model_set_damping_csc(fe, n, colptr, rowind, values) &
        bind(C, name="jprom_fe_model_set_damping_csc")
      import :: c_int, c_ptr, c_size_t, c_double
      type(c_ptr), value :: fe
      integer(c_size_t), value :: n
      integer(c_size_t), dimension(*), intent(in) :: colptr, rowind
      real(c_double), dimension(*), intent(in) :: values
    end function
    integer(c_int) function jprom_fe_model_fix_dof(fe, node, direction) bind(C, name="jprom_fe_model_fix_dof")
      import :: c_int, c_ptr, c_int64_t, c_size_t
      type(c_ptr), value :: fe
      integer(c_int64_t), value :: node
      integer(c_size_t), value :: direction
    end function
    !> Deprecated: use jprom_fe_model_fix_dof.
    integer(c_int) function jprom_fe_fix_dof(fe, node, direction) bind(C, name="jprom_fe_fix_dof")
      import :: c_int, c_ptr, c_int64_t, c_size_t
      type(c_ptr), value :: fe
      integer(c_int64_t), value :: node
      integer(c_size_t), value :: direction
    end function
    integer(c_int) function jprom_fe_model_reduce_cutoff(fe, cutoff_hz, max_modes, model) &
        bind(C, name="jprom_fe_model_reduce_cutoff")
      import :: c_int, c_ptr, c_size_t, c_double
      type(c_ptr), value :: fe
      real(c_double), value :: cutoff_hz
      integer(c_size_t), value :: max_modes
      type(c_ptr), intent(out) :: model
    end function
    !> Deprecated: use jprom_fe_model_reduce_cutoff.
    integer(c_int) function jprom_fe_reduce_cutoff(fe, cutoff_hz, max_modes, model) bind(C, name="jprom_fe_reduce_cutoff")
      import :: c_int, c_ptr, c_size_t, c_double
      type(c_ptr), value :: fe
      real(c_double), value :: cutoff_hz
      integer(c_size_t), value :: max_modes
      type(c_ptr), intent(out) :: model
    end function
    integer(c_int) function jprom_fe_model_modes(fe, n_modes, frequency_hz) bind(C, name="jprom_fe_model_modes")
      import :: c_int, c_ptr, c_size_t, c_double
      type(c_ptr), value :: fe
      integer(c_size_t), value :: n_modes
      real(c_double), dimension(*), intent(out) :: frequency_hz
    end function
  end interface
end module jprom_c

module jprom
  use, intrinsic :: iso_c_binding
  use jprom_c, only: jprom_hbm_options, jprom_sweep_options, jprom_jp_options, &
                     JPROM_OK, JPROM_NULL_ARGUMENT, JPROM_BAD_SIZE, JPROM_INVALID_VALUE, JPROM_SINGULAR_MATRIX, &
                     JPROM_NO_CONVERGENCE, JPROM_IO, JPROM_PANIC, JPROM_CANCELLED, JPROM_INVALID_HANDLE, JPROM_EIGEN, &
                     JPROM_PARSE, JPROM_CALLBACK_ERROR, JPROM_ROM_FR, JPROM_ROM_NLR, JPROM_CORRECTION_REGENERATED, &
                     JPROM_CORRECTION_GAMMA_INCREASED, JPROM_CORRECTION_REPLACED, JPROM_CORRECTIONS_WITHIN_THRESHOLD, &
                     JPROM_CORRECTIONS_MAX_CORRECTIONS, JPROM_CORRECTIONS_NO_PROGRESS, JPROM_CORRECTIONS_CANCELLED, &
                     JPROM_SLIPPING_NEVER, &
                     JPROM_SLIPPING_AT_GROSS_SLIP, JPROM_SLIPPING_ALWAYS, JPROM_SWEEP_REACHED_END, JPROM_SWEEP_STALLED, &
                     JPROM_SWEEP_POINT_CAP, JPROM_SWEEP_LEFT_BAND, JPROM_SWEEP_CANCELLED, JPROM_EVENT_FOLD, &
                     JPROM_EVENT_BRANCH_POINT, JPROM_MAX_HARMONICS, &
                     JPROM_MAX_NT, JPROM_MAX_SAMPLES, JPROM_DENSE_MAX_DOF, JPROM_MAX_FORCE_HARMONIC
  implicit none
  private
  public :: jprom_hbm_options, jprom_sweep_options, jprom_jp_options
  public :: JPROM_OK, JPROM_NULL_ARGUMENT, JPROM_BAD_SIZE, JPROM_INVALID_VALUE, JPROM_SINGULAR_MATRIX, &
            JPROM_NO_CONVERGENCE, JPROM_IO, JPROM_PANIC, JPROM_CANCELLED, JPROM_INVALID_HANDLE, JPROM_EIGEN, JPROM_PARSE, &
            JPROM_CALLBACK_ERROR
  public :: JPROM_ROM_FR, JPROM_ROM_NLR, JPROM_CORRECTION_REGENERATED, JPROM_CORRECTION_GAMMA_INCREASED, &
            JPROM_CORRECTION_REPLACED
  public :: JPROM_CORRECTIONS_WITHIN_THRESHOLD, JPROM_CORRECTIONS_MAX_CORRECTIONS, JPROM_CORRECTIONS_NO_PROGRESS, &
            JPROM_CORRECTIONS_CANCELLED
  public :: JPROM_SLIPPING_NEVER, JPROM_SLIPPING_AT_GROSS_SLIP, JPROM_SLIPPING_ALWAYS
  public :: JPROM_SWEEP_REACHED_END, JPROM_SWEEP_STALLED, JPROM_SWEEP_POINT_CAP, JPROM_SWEEP_LEFT_BAND, &
            JPROM_SWEEP_CANCELLED
  public :: JPROM_EVENT_FOLD, JPROM_EVENT_BRANCH_POINT
  public :: JPROM_MAX_HARMONICS, JPROM_MAX_NT, JPROM_MAX_SAMPLES, JPROM_DENSE_MAX_DOF, JPROM_MAX_FORCE_HARMONIC
  ! errors, version, diagnostics
  public :: jp_last_error, jp_status_name, jp_version, jp_live_handle_count, jp_set_memory_budget, jp_memory_budget
  public :: jp_set_reproducible, jp_reproducible, jp_set_time_budget, jp_time_budget
  ! models
  public :: jp_model_new, jp_model_new_csc, jp_model_clone, jp_model_free, jp_model_sizes, jp_add_ground_contact, &
            jp_add_contact, jp_add_jenkins, jp_add_polynomial_spring, jp_add_unilateral_spring, jp_add_friction_2d, &
            jp_add_element_callback, &
            jp_set_damping, jp_set_modal_damping, jp_set_static_force, &
            jp_set_first_harmonic_force, jp_set_harmonic_force, jp_set_dynamic_scale, jp_set_excitation_level, &
            jp_excitation_level, jp_set_outputs, jp_model_validate, jp_model_save, jp_model_load
  ! options
  public :: jp_default_options, jp_default_jp_options
  ! solutions and sweeps
  public :: jp_solve_point, jp_solve_point_from, jp_solution_free, jp_solution_omega, jp_solution_sizes, jp_solution_coeffs, &
            jp_solution_amplitude, jp_solution_convergence, jp_solution_energy, jp_solution_n_samples, &
            jp_solution_contact_states, jp_solution_save, jp_solution_load
  public :: jp_sweep, jp_sweep_from, jp_sweep_free, jp_sweep_n_points, jp_sweep_end, jp_sweep_end_name, jp_sweep_reached_end, &
            jp_sweep_point, jp_sweep_point_coeffs, jp_sweep_point_energy, jp_sweep_point_convergence, &
            jp_sweep_solution, jp_sweep_save, jp_sweep_load
  public :: jp_sweep_n_events, jp_sweep_event, jp_event_kind_name, jp_sweep_n_gaps, jp_sweep_gap
  ! JP reduction
  public :: jp_basis_predict, jp_basis_from_solution, jp_basis_sizes, jp_basis_free, jp_basis_save, jp_basis_load, &
            jp_rom_sweep, jp_rom_sweep_adaptive, jp_sweep_point_error, jp_sweep_n_corrections, jp_sweep_correction, &
            jp_correction_kind_name, jp_sweep_correction_end, jp_correction_end_name, jp_rom_actual_error, &
            jp_sweep_static_error, jp_sweep_correction_swept, jp_sweep_trust, jp_sweep_judged_error
  ! FE models
  public :: jp_fe_new_csc, jp_fe_load_calculix, jp_fe_free, jp_fe_n_dof, jp_fe_node_set, jp_fe_add_contact, &
            jp_fe_add_force, jp_fe_add_output, jp_fe_keep_node, jp_fe_reduce, jp_fe_unreduced
  ! damping forms and natural modes
  public :: jp_set_damping_matrix, jp_set_modal_damping_ratios, jp_set_loss_factor, jp_model_modes, &
            jp_fe_set_damping_csc, jp_fe_modes, jp_fe_fix_dof, jp_fe_reduce_cutoff

  interface
    ! the C library's strlen, to read the library's NUL-terminated strings
    integer(c_size_t) pure function c_strlen(s) bind(C, name="strlen")
      import :: c_size_t, c_ptr
      type(c_ptr), value, intent(in) :: s
    end function
  end interface

contains

  ! ---- helpers ----

  !> A NUL-terminated C string (static or thread-local storage of the library) as a Fortran string.
  function from_c(p) result(s)
    type(c_ptr), intent(in) :: p
    character(len=:), allocatable :: s
    character(kind=c_char), pointer :: chars(:)
    integer :: i, n
    if (.not. c_associated(p)) then
      s = ''
      return
    end if
    n = int(c_strlen(p))
    call c_f_pointer(p, chars, [n])
    allocate (character(len=n) :: s)
    do i = 1, n
      s(i:i) = chars(i)
    end do
  end function

  !> A Fortran string (trailing blanks trimmed) as a NUL-terminated C string.
  pure function to_c(s) result(c)
    character(len=*), intent(in) :: s
    character(kind=c_char, len=len_trim(s) + 1) :: c
    c = trim(s) // c_null_char
  end function

  !> 1-based Fortran indices to the C API's 0-based ones.
  elemental integer(c_size_t) function c_index(i)
    integer, intent(in) :: i
    c_index = int(i - 1, c_size_t)
  end function

  !> The last error message of this thread, as a Fortran string.
  subroutine jp_last_error(message)
    use jprom_c, only: jprom_last_error_copy
    character(len=*), intent(out) :: message
    character(kind=c_char) :: buf(1024)
    integer(c_size_t) :: written
    integer :: i, n, s
    s = jprom_last_error_copy(buf, int(size(buf), c_size_t), written)
    message = ' '
    n = int(min(written, int(size(buf) - 1, c_size_t)))
    do i = 1, min(n, len(message))
      message(i:i) = buf(i)
    end do
  end subroutine

  integer function finish(status, message)
    integer(c_int), intent(in) :: status
    character(len=*), intent(out), optional :: message
    finish = int(status)
    if (present(message)) then
      message = ' '
      if (status /= JPROM_OK) call jp_last_error(message)
    end if
  end function

  !> A failure found by this layer before calling C (an array of the wrong size).
  integer function refuse(status, why, message)
    integer(c_int), intent(in) :: status
    character(len=*), intent(in) :: why
    character(len=*), intent(out), optional :: message
    refuse = int(status)
    if (present(message)) message = why
  end function

  ! ---- errors, version, diagnostics ----

  !> The name of a status code ("JPROM_OK", "JPROM_BAD_SIZE", ...).
  function jp_status_name(status) result(name)
    use jprom_c, only: jprom_status_name
    integer, intent(in) :: status
    character(len=:), allocatable :: name
    name = from_c(jprom_status_name(int(status, c_int)))
  end function

  !> The library's version ("MAJOR.MINOR.PATCH"), which may be newer than the one this binding was written for.
  function jp_version() result(version)
    use jprom_c, only: jprom_version
    character(len=:), allocatable :: version
    version = from_c(jprom_version())
  end function

  !> Number of live handles of all kinds in the process (a leak check).
  integer function jp_live_handle_count(n)
    use jprom_c, only: jprom_live_handle_count
    integer, intent(out) :: n
    integer(c_size_t) :: m
    jp_live_handle_count = int(jprom_live_handle_count(m))
    if (jp_live_handle_count == JPROM_OK) n = int(m)
  end function

  !> The memory budget in bytes for one request (0 restores the default, 70 % of the memory).
  integer function jp_set_memory_budget(bytes)
    use jprom_c, only: jprom_set_memory_budget
    integer(c_size_t), intent(in) :: bytes
    jp_set_memory_budget = int(jprom_set_memory_budget(bytes))
  end function

  integer function jp_memory_budget(bytes)
    use jprom_c, only: jprom_memory_budget
    integer(c_size_t), intent(out) :: bytes
    jp_memory_budget = int(jprom_memory_budget(bytes))
  end function

  !> The time budget in seconds for stages whose cost grows with H (jprom_set_time_budget);
  !> 0 restores the default of 3600 s.
  integer function jp_set_time_budget(seconds)
    use jprom_c, only: jprom_set_time_budget
    real(c_double), intent(in) :: seconds
    jp_set_time_budget = int(jprom_set_time_budget(seconds))
  end function

  integer function jp_time_budget(seconds)
    use jprom_c, only: jprom_time_budget
    real(c_double), intent(out) :: seconds
    jp_time_budget = int(jprom_time_budget(seconds))
  end function

  !> Kernels on one thread (on = .true.), so that results do not depend on the thread count
  !> (jprom_set_reproducible); .false. restores the default, kernels on all threads.
  integer function jp_set_reproducible(on)
    use jprom_c, only: jprom_set_reproducible
    logical, intent(in) :: on
    jp_set_reproducible = int(jprom_set_reproducible(merge(1_c_int, 0_c_int, on)))
  end function

  integer function jp_reproducible(on)
    use jprom_c, only: jprom_reproducible
    logical, intent(out) :: on
    integer(c_int) :: v
    jp_reproducible = int(jprom_reproducible(v))
    on = v /= 0
  end function

  ! ---- models ----

  !> New model from n x n column-major mass and stiffness matrices.
  integer function jp_model_new(mass, stiffness, model, message)
    use jprom_c, only: jprom_model_new
    real(c_double), intent(in) :: mass(:, :), stiffness(:, :)
    type(c_ptr), intent(out) :: model
    character(len=*), intent(out), optional :: message
    if (size(mass, 1) /= size(mass, 2) .or. any(shape(stiffness) /= shape(mass))) then
      jp_model_new = refuse(JPROM_BAD_SIZE, 'jp_model_new: mass and stiffness must be n x n', message)
      return
    end if
    jp_model_new = finish(jprom_model_new(int(size(mass, 1), c_size_t), mass, stiffness, model), message)
  end function

  !> New model from n x n sparse mass and stiffness matrices in compressed sparse column form,
  !> 1-BASED: colptr(n + 1) with colptr(1) = 1, rowind and values of colptr(n + 1) - 1 entries
  !> (both triangles; duplicates are summed). Stored dense: n <= JPROM_DENSE_MAX_DOF.
  integer function jp_model_new_csc(n, mass_colptr, mass_rowind, mass_values, stiffness_colptr, stiffness_rowind, &
                                    stiffness_values, model, message)
    use jprom_c, only: jprom_model_new_csc
    integer, intent(in) :: n, mass_colptr(:), mass_rowind(:), stiffness_colptr(:), stiffness_rowind(:)
    real(c_double), intent(in) :: mass_values(:), stiffness_values(:)
    type(c_ptr), intent(out) :: model
    character(len=*), intent(out), optional :: message
    if (.not. (csc_fits(n, mass_colptr, mass_rowind, mass_values) .and. &
               csc_fits(n, stiffness_colptr, stiffness_rowind, stiffness_values))) then
      jp_model_new_csc = refuse(JPROM_BAD_SIZE, 'jp_model_new_csc: colptr must have n + 1 entries and rowind, values ' // &
                                'colptr(n + 1) - 1', message)
      return
    end if
    jp_model_new_csc = finish(jprom_model_new_csc(int(n, c_size_t), c_index(mass_colptr), c_index(mass_rowind), &
                                                  mass_values, c_index(stiffness_colptr), c_index(stiffness_rowind), &
                                                  stiffness_values, model), message)
  end function

  !> Whether 1-based CSC arrays have the sizes the C API will read (their values it checks itself).
  pure logical function csc_fits(n, colptr, rowind, values)
    integer, intent(in) :: n, colptr(:), rowind(:)
    real(c_double), intent(in) :: values(:)
    csc_fits = .false.
    if (n < 0 .or. size(colptr) /= n + 1) return
    if (colptr(n + 1) < 1) return
    csc_fits = size(rowind) >= colptr(n + 1) - 1 .and. size(values) >= colptr(n + 1) - 1
  end function

  !> A deep copy of a model (free both).
  integer function jp_model_clone(model, copy, message)
    use jprom_c, only: jprom_model_clone
    type(c_ptr), intent(in) :: model
    type(c_ptr), intent(out) :: copy
    character(len=*), intent(out), optional :: message
    jp_model_clone = finish(jprom_model_clone(model, copy), message)
  end function

  integer function jp_model_free(model)
    use jprom_c, only: jprom_model_free
    type(c_ptr), intent(inout) :: model
    jp_model_free = int(jprom_model_free(model))
    model = c_null_ptr
  end function

  !> The model's DoF, contact and output counts.
  integer function jp_model_sizes(model, n_dof, n_contacts, n_outputs, message)
    use jprom_c, only: jprom_model_n_dof, jprom_model_n_contacts, jprom_model_n_outputs
    type(c_ptr), intent(in) :: model
    integer, intent(out) :: n_dof, n_contacts, n_outputs
    character(len=*), intent(out), optional :: message
    integer(c_size_t) :: d, c, o
    integer(c_int) :: s
    s = jprom_model_n_dof(model, d)
    if (s == JPROM_OK) s = jprom_model_n_contacts(model, c)
    if (s == JPROM_OK) s = jprom_model_n_outputs(model, o)
    jp_model_sizes = finish(s, message)
    if (s == JPROM_OK) then
      n_dof = int(d); n_contacts = int(c); n_outputs = int(o)
    end if
  end function

  !> 3D friction contact of node `dofs` (three 1-based DoF numbers) against ground;
  !> frame(3, 3): rows t1, t2, n (frame(i, :) is axis i).
  integer function jp_add_ground_contact(model, dofs, frame, kt1, kt2, kn, mu, n0, message)
    use jprom_c, only: jprom_model_add_contact_3d
    type(c_ptr), intent(in) :: model
    integer, intent(in) :: dofs(3)
    real(c_double), intent(in) :: frame(3, 3), kt1, kt2, kn, mu, n0
    character(len=*), intent(out), optional :: message
    integer(c_size_t) :: a(3)
    real(c_double) :: rows(9)
    a = c_index(dofs)
    rows = reshape(transpose(frame), [9])
    jp_add_ground_contact = finish(jprom_model_add_contact_3d(model, a, c_null_ptr, rows, kt1, kt2, kn, mu, n0), message)
  end function

  !> 3D friction contact between two nodes: DoFs dofs_a(3) and dofs_b(3) (1-based), relative
  !> displacement a - b in the frame(3, 3) (rows t1, t2, n).
  integer function jp_add_contact(model, dofs_a, dofs_b, frame, kt1, kt2, kn, mu, n0, message)
    use jprom_c, only: jprom_model_add_contact_3d
    type(c_ptr), intent(in) :: model
    integer, intent(in) :: dofs_a(3), dofs_b(3)
    real(c_double), intent(in) :: frame(3, 3), kt1, kt2, kn, mu, n0
    character(len=*), intent(out), optional :: message
    integer(c_size_t) :: a(3)
    integer(c_size_t), target :: b(3)
    real(c_double) :: rows(9)
    a = c_index(dofs_a)
    b = c_index(dofs_b)
    rows = reshape(transpose(frame), [9])
    jp_add_contact = finish(jprom_model_add_contact_3d(model, a, c_loc(b), rows, kt1, kt2, kn, mu, n0), message)
  end function

  !> 1D Jenkins element (spring kt in series with a slider of limit mu * normal_load) on DoF
  !> dof_a (1-based), against ground, or relative to DoF dof_b when present.
  integer function jp_add_jenkins(model, dof_a, kt, mu, normal_load, dof_b, message)
    use jprom_c, only: jprom_model_add_jenkins
    type(c_ptr), intent(in) :: model
    integer, intent(in) :: dof_a
    real(c_double), intent(in) :: kt, mu, normal_load
    integer, intent(in), optional :: dof_b
    character(len=*), intent(out), optional :: message
    integer(c_size_t), target :: b
    type(c_ptr) :: pb
    pb = c_null_ptr
    if (present(dof_b)) then
      b = c_index(dof_b)
      pb = c_loc(b)
    end if
    jp_add_jenkins = finish(jprom_model_add_jenkins(model, c_index(dof_a), pb, kt, mu, normal_load), message)
  end function

  !> Polynomial spring F(w) = sum_p coefficients(p) w**p (p = 1..size(coefficients); the cubic
  !> k1 w + k3 w**3 is [k1, 0, k3]) on DoF dof_a (1-based), w = x(dof_a) against ground, or
  !> x(dof_a) - x(dof_b) when dof_b is present.
  integer function jp_add_polynomial_spring(model, dof_a, coefficients, dof_b, message)
    use jprom_c, only: jprom_model_add_polynomial_spring
    type(c_ptr), intent(in) :: model
    integer, intent(in) :: dof_a
    real(c_double), intent(in) :: coefficients(:)
    integer, intent(in), optional :: dof_b
    character(len=*), intent(out), optional :: message
    integer(c_size_t), target :: b
    type(c_ptr) :: pb
    real(c_double) :: c(max(size(coefficients), 1))
    pb = c_null_ptr
    if (present(dof_b)) then
      b = c_index(dof_b)
      pb = c_loc(b)
    end if
    c = 0
    c(1:size(coefficients)) = coefficients
    jp_add_polynomial_spring = finish(jprom_model_add_polynomial_spring(model, c_index(dof_a), pb, c, &
        int(size(coefficients), c_size_t)), message)
  end function

  !> Unilateral spring N = max(0, n0 + kn v) on DoF dof_a (1-based), v = x(dof_a) against
  !> ground, or x(dof_a) - x(dof_b) when dof_b is present; a gap g is n0 = -kn g.
  integer function jp_add_unilateral_spring(model, dof_a, kn, n0, dof_b, message)
    use jprom_c, only: jprom_model_add_unilateral_spring
    type(c_ptr), intent(in) :: model
    integer, intent(in) :: dof_a
    real(c_double), intent(in) :: kn, n0
    integer, intent(in), optional :: dof_b
    character(len=*), intent(out), optional :: message
    integer(c_size_t), target :: b
    type(c_ptr) :: pb
    pb = c_null_ptr
    if (present(dof_b)) then
      b = c_index(dof_b)
      pb = c_loc(b)
    end if
    jp_add_unilateral_spring = finish(jprom_model_add_unilateral_spring(model, c_index(dof_a), pb, kn, n0), message)
  end function

  !> 2D friction element on the DoFs dofs_a(2) (1-based), against ground, or relative to
  !> dofs_b(2) when present, in the frame(2, 2) (rows t, n): tangential kt with friction mu,
  !> normal kn with preload n0.
  integer function jp_add_friction_2d(model, dofs_a, frame, kt, kn, mu, n0, dofs_b, message)
    use jprom_c, only: jprom_model_add_friction_2d
    type(c_ptr), intent(in) :: model
    integer, intent(in) :: dofs_a(2)
    real(c_double), intent(in) :: frame(2, 2), kt, kn, mu, n0
    integer, intent(in), optional :: dofs_b(2)
    character(len=*), intent(out), optional :: message
    integer(c_size_t) :: a(2)
    integer(c_size_t), target :: b(2)
    real(c_double) :: rows(4)
    type(c_ptr) :: pb
    a = c_index(dofs_a)
    pb = c_null_ptr
    if (present(dofs_b)) then
      b = c_index(dofs_b)
      pb = c_loc(b)
    end if
    rows = reshape(transpose(frame), [4])
    jp_add_friction_2d = finish(jprom_model_add_friction_2d(model, a, pb, rows, kt, kn, mu, n0), message)
  end function

  !> User-defined memoryless element on dim = 1..3 local coordinates: dofs_a(dim) (1-based),
  !> against ground, or relative to dofs_b(dim) when present, in frame(dim, dim) (rows: local
  !> axes; identity when absent). callback = c_funloc of a bind(C) function (see the raw
  !> interface jprom_model_add_element_callback) called per AFT time sample with user_data;
  !> it must be thread-safe, and user_data must stay valid while the model lives. A nonzero
  !> return ends a solve with JPROM_CALLBACK_ERROR.
  integer function jp_add_element_callback(model, dim, dofs_a, callback, user_data, frame, dofs_b, message)
    use jprom_c, only: jprom_model_add_element_callback
    type(c_ptr), intent(in) :: model
    integer, intent(in) :: dim
    integer, intent(in) :: dofs_a(dim)
    type(c_funptr), intent(in) :: callback
    type(c_ptr), intent(in) :: user_data
    real(c_double), intent(in), optional :: frame(dim, dim)
    integer, intent(in), optional :: dofs_b(dim)
    character(len=*), intent(out), optional :: message
    integer(c_size_t) :: a(3)
    integer(c_size_t), target :: b(3)
    real(c_double), target :: rows(9)
    type(c_ptr) :: pb, pf
    if (dim < 1 .or. dim > 3) then
      ! let the library refuse it with its message
      a = 0
      jp_add_element_callback = finish(jprom_model_add_element_callback(model, int(max(dim, 0), c_size_t), a, &
                                                                        c_null_ptr, c_null_ptr, callback, user_data), message)
      return
    end if
    a(1:dim) = c_index(dofs_a)
    pb = c_null_ptr
    if (present(dofs_b)) then
      b(1:dim) = c_index(dofs_b)
      pb = c_loc(b)
    end if
    pf = c_null_ptr
    if (present(frame)) then
      rows(1:dim * dim) = reshape(transpose(frame), [dim * dim])
      pf = c_loc(rows)
    end if
    jp_add_element_callback = finish(jprom_model_add_element_callback(model, int(dim, c_size_t), a, pb, pf, callback, &
                                                                      user_data), message)
  end function

  !> Rayleigh damping C = alpha M + beta K.
  integer function jp_set_damping(model, alpha, beta, message)
    use jprom_c, only: jprom_model_set_rayleigh_damping
    type(c_ptr), intent(in) :: model
    real(c_double), intent(in) :: alpha, beta
    character(len=*), intent(out), optional :: message
    jp_set_damping = finish(jprom_model_set_rayleigh_damping(model, alpha, beta), message)
  end function

  !> Stiffness-proportional damping with modal ratio zeta at angular frequency omega.
  integer function jp_set_modal_damping(model, zeta, omega, message)
    use jprom_c, only: jprom_model_set_modal_damping
    type(c_ptr), intent(in) :: model
    real(c_double), intent(in) :: zeta, omega
    character(len=*), intent(out), optional :: message
    jp_set_modal_damping = finish(jprom_model_set_modal_damping(model, zeta, omega), message)
  end function

  !> Static force f_E^0 (n_dof values).
  integer function jp_set_static_force(model, force, message)
    use jprom_c, only: jprom_model_set_static_force
    type(c_ptr), intent(in) :: model
    real(c_double), intent(in) :: force(:)
    character(len=*), intent(out), optional :: message
    jp_set_static_force = finish(jprom_model_set_static_force(model, force, int(size(force), c_size_t)), message)
  end function

  !> Force of harmonic h = 1..JPROM_MAX_FORCE_HARMONIC: cos and sin parts (n_dof values each).
  integer function jp_set_harmonic_force(model, h, cos_part, sin_part, message)
    use jprom_c, only: jprom_model_set_harmonic_force
    type(c_ptr), intent(in) :: model
    integer, intent(in) :: h
    real(c_double), intent(in) :: cos_part(:), sin_part(:)
    character(len=*), intent(out), optional :: message
    if (size(sin_part) /= size(cos_part)) then
      jp_set_harmonic_force = refuse(JPROM_BAD_SIZE, 'jp_set_harmonic_force: cos_part and sin_part differ in size', message)
      return
    end if
    jp_set_harmonic_force = finish(jprom_model_set_harmonic_force(model, int(h, c_size_t), cos_part, sin_part, &
                                                                  int(size(cos_part), c_size_t)), message)
  end function

  integer function jp_set_first_harmonic_force(model, cos_part, sin_part, message)
    type(c_ptr), intent(in) :: model
    real(c_double), intent(in) :: cos_part(:), sin_part(:)
    character(len=*), intent(out), optional :: message
    jp_set_first_harmonic_force = jp_set_harmonic_force(model, 1, cos_part, sin_part, message)
  end function

  !> Scale of the harmonic excitation.
  integer function jp_set_dynamic_scale(model, scale, message)
    use jprom_c, only: jprom_model_set_dynamic_scale
    type(c_ptr), intent(in) :: model
    real(c_double), intent(in) :: scale
    character(len=*), intent(out), optional :: message
    jp_set_dynamic_scale = finish(jprom_model_set_dynamic_scale(model, scale), message)
  end function

  !> Sets the dynamic scale so that |f_E^0| / |f_E^1| = alpha.
  integer function jp_set_excitation_level(model, alpha, message)
    use jprom_c, only: jprom_model_set_excitation_level
    type(c_ptr), intent(in) :: model
    real(c_double), intent(in) :: alpha
    character(len=*), intent(out), optional :: message
    jp_set_excitation_level = finish(jprom_model_set_excitation_level(model, alpha), message)
  end function

  integer function jp_excitation_level(model, alpha, message)
    use jprom_c, only: jprom_model_excitation_level
    type(c_ptr), intent(in) :: model
    real(c_double), intent(out) :: alpha
    character(len=*), intent(out), optional :: message
    jp_excitation_level = finish(jprom_model_excitation_level(model, alpha), message)
  end function

  !> Output DoFs, 1-based.
  integer function jp_set_outputs(model, dofs, message)
    use jprom_c, only: jprom_model_set_output_dofs
    type(c_ptr), intent(in) :: model
    integer, intent(in) :: dofs(:)
    character(len=*), intent(out), optional :: message
    jp_set_outputs = finish(jprom_model_set_output_dofs(model, c_index(dofs), int(size(dofs), c_size_t)), message)
  end function

  !> Checks the model as a sweep would (contacts, forces, outputs); JPROM_OK if usable.
  integer function jp_model_validate(model, message)
    use jprom_c, only: jprom_model_validate
    type(c_ptr), intent(in) :: model
    character(len=*), intent(out), optional :: message
    jp_model_validate = finish(jprom_model_validate(model), message)
  end function

  integer function jp_model_save(model, path, message)
    use jprom_c, only: jprom_model_save_json
    type(c_ptr), intent(in) :: model
    character(len=*), intent(in) :: path
    character(len=*), intent(out), optional :: message
    jp_model_save = finish(jprom_model_save_json(model, to_c(path)), message)
  end function

  integer function jp_model_load(path, model, message)
    use jprom_c, only: jprom_model_load_json
    character(len=*), intent(in) :: path
    type(c_ptr), intent(out) :: model
    character(len=*), intent(out), optional :: message
    jp_model_load = finish(jprom_model_load_json(to_c(path), model), message)
  end function

  ! ---- options ----

  !> Defaults of the harmonic balance and sweep options (every field of this binding's structs).
  subroutine jp_default_options(opts, sweep_opts)
    use jprom_c, only: jprom_hbm_options_init, jprom_sweep_options_init
    type(jprom_hbm_options), intent(out) :: opts
    type(jprom_sweep_options), intent(out) :: sweep_opts
    integer(c_int) :: s
    s = jprom_hbm_options_init(opts, c_sizeof(opts))
    s = jprom_sweep_options_init(sweep_opts, c_sizeof(sweep_opts))
  end subroutine

  !> Defaults of the JP basis and self-correcting sweep settings (gamma 1e3, 100 samples,
  !> threshold 0.05 on e*_1, at most 5 corrections, ...).
  subroutine jp_default_jp_options(jp_opts)
    use jprom_c, only: jprom_jp_options_init
    type(jprom_jp_options), intent(out) :: jp_opts
    integer(c_int) :: s
    s = jprom_jp_options_init(jp_opts, c_sizeof(jp_opts))
  end subroutine

  ! ---- solutions ----

  !> The full-order periodic solution at angular frequency omega.
  integer function jp_solve_point(model, omega, opts, solution, message)
    use jprom_c, only: jprom_solve_point
    type(c_ptr), intent(in) :: model
    real(c_double), intent(in) :: omega
    type(jprom_hbm_options), intent(in) :: opts
    type(c_ptr), intent(out) :: solution
    character(len=*), intent(out), optional :: message
    jp_solve_point = finish(jprom_solve_point(model, omega, opts, solution), message)
  end function

  !> The full-order solution at omega from the solution guess (c_null_ptr: from zero), for
  !> example the nearest point of a sweep; guess must come from a full-order solve with the
  !> same opts%condensed (its harmonics may differ).
  integer function jp_solve_point_from(model, omega, opts, guess, solution, message)
    use jprom_c, only: jprom_solve_point_from
    type(c_ptr), intent(in) :: model
    real(c_double), intent(in) :: omega
    type(jprom_hbm_options), intent(in) :: opts
    type(c_ptr), intent(in) :: guess
    type(c_ptr), intent(out) :: solution
    character(len=*), intent(out), optional :: message
    jp_solve_point_from = finish(jprom_solve_point_from(model, omega, opts, guess, solution), message)
  end function

  integer function jp_solution_free(solution)
    use jprom_c, only: jprom_solution_free
    type(c_ptr), intent(inout) :: solution
    jp_solution_free = int(jprom_solution_free(solution))
    solution = c_null_ptr
  end function

  integer function jp_solution_omega(solution, omega)
    use jprom_c, only: jprom_solution_omega
    type(c_ptr), intent(in) :: solution
    real(c_double), intent(out) :: omega
    jp_solution_omega = int(jprom_solution_omega(solution, omega))
  end function

  !> Harmonics H, outputs and contacts of a solution.
  integer function jp_solution_sizes(solution, harmonics, n_outputs, n_contacts)
    use jprom_c, only: jprom_solution_sizes
    type(c_ptr), intent(in) :: solution
    integer, intent(out) :: harmonics, n_outputs, n_contacts
    integer(c_size_t) :: h, o, c
    jp_solution_sizes = int(jprom_solution_sizes(solution, h, o, c))
    if (jp_solution_sizes == JPROM_OK) then
      harmonics = int(h); n_outputs = int(o); n_contacts = int(c)
    end if
  end function

  !> Every harmonic coefficient at every output: coeffs(n_outputs, 2H + 1), coeffs(j, k + 1) as
  !> at the top of this file.
  integer function jp_solution_coeffs(solution, coeffs, message)
    use jprom_c, only: jprom_solution_output_coeffs
    type(c_ptr), intent(in) :: solution
    real(c_double), contiguous, intent(inout) :: coeffs(:, :)
    character(len=*), intent(out), optional :: message
    jp_solution_coeffs = finish(jprom_solution_output_coeffs(solution, coeffs, int(size(coeffs), c_size_t)), message)
  end function

  !> Amplitude sqrt(cos^2 + sin^2) of harmonic h (0: |static|) at output j (1-based).
  integer function jp_solution_amplitude(solution, h, j, amplitude)
    use jprom_c, only: jprom_solution_amplitude
    type(c_ptr), intent(in) :: solution
    integer, intent(in) :: h, j
    real(c_double), intent(out) :: amplitude
    jp_solution_amplitude = int(jprom_solution_amplitude(solution, int(h, c_size_t), c_index(j), amplitude))
  end function

  !> Newton iterations and final relative residual of a solution.
  integer function jp_solution_convergence(solution, iterations, residual)
    use jprom_c, only: jprom_solution_convergence
    type(c_ptr), intent(in) :: solution
    integer, intent(out) :: iterations
    real(c_double), intent(out) :: residual
    integer(c_size_t) :: it
    jp_solution_convergence = int(jprom_solution_convergence(solution, it, residual))
    if (jp_solution_convergence == JPROM_OK) iterations = int(it)
  end function

  !> Energy dissipated per cycle by each contact: energy(1:n_contacts).
  integer function jp_solution_energy(solution, energy, message)
    use jprom_c, only: jprom_solution_dissipated_energy
    type(c_ptr), intent(in) :: solution
    real(c_double), intent(inout) :: energy(:)
    character(len=*), intent(out), optional :: message
    real(c_double) :: buf(size(energy))
    integer(c_int) :: s
    s = jprom_solution_dissipated_energy(solution, buf, int(size(energy), c_size_t))
    if (s == JPROM_OK) energy = buf
    jp_solution_energy = finish(s, message)
  end function

  !> AFT time samples per contact in the solution's state record.
  integer function jp_solution_n_samples(solution, n)
    use jprom_c, only: jprom_solution_n_samples
    type(c_ptr), intent(in) :: solution
    integer, intent(out) :: n
    integer(c_size_t) :: m
    jp_solution_n_samples = int(jprom_solution_n_samples(solution, m))
    if (jp_solution_n_samples == JPROM_OK) n = int(m)
  end function

  !> States (0 stick, 1 slip, 2 separated) of contact `contact` (1-based) at each time sample:
  !> states(1:n_samples).
  integer function jp_solution_contact_states(solution, contact, states, message)
    use jprom_c, only: jprom_solution_contact_states
    type(c_ptr), intent(in) :: solution
    integer, intent(in) :: contact
    integer, intent(inout) :: states(:)
    character(len=*), intent(out), optional :: message
    integer(c_int8_t) :: buf(size(states))
    integer(c_int) :: s
    s = jprom_solution_contact_states(solution, c_index(contact), buf, int(size(states), c_size_t))
    if (s == JPROM_OK) states = int(buf)
    jp_solution_contact_states = finish(s, message)
  end function

  integer function jp_solution_save(solution, path, message)
    use jprom_c, only: jprom_solution_save_json
    type(c_ptr), intent(in) :: solution
    character(len=*), intent(in) :: path
    character(len=*), intent(out), optional :: message
    jp_solution_save = finish(jprom_solution_save_json(solution, to_c(path)), message)
  end function

  integer function jp_solution_load(path, solution, message)
    use jprom_c, only: jprom_solution_load_json
    character(len=*), intent(in) :: path
    type(c_ptr), intent(out) :: solution
    character(len=*), intent(out), optional :: message
    jp_solution_load = finish(jprom_solution_load_json(to_c(path), solution), message)
  end function

  ! ---- sweeps ----

  !> Frequency sweep over [sweep_opts%omega_start, sweep_opts%omega_end]. For a progress
  !> callback call jprom_sweep of module jprom_c with c_funloc of a bind(C) function.
  integer function jp_sweep(model, opts, sweep_opts, sweep, message)
    use jprom_c, only: jprom_sweep
    type(c_ptr), intent(in) :: model
    type(jprom_hbm_options), intent(in) :: opts
    type(jprom_sweep_options), intent(in) :: sweep_opts
    type(c_ptr), intent(out) :: sweep
    character(len=*), intent(out), optional :: message
    jp_sweep = finish(jprom_sweep(model, opts, sweep_opts, c_null_funptr, c_null_ptr, sweep), message)
  end function

  !> As jp_sweep, with the first point (at sweep_opts%omega_start) solved from the solution
  !> start (c_null_ptr: from zero): restarts a sweep from one of its points.
  integer function jp_sweep_from(model, opts, sweep_opts, start, sweep, message)
    use jprom_c, only: jprom_sweep_from
    type(c_ptr), intent(in) :: model
    type(jprom_hbm_options), intent(in) :: opts
    type(jprom_sweep_options), intent(in) :: sweep_opts
    type(c_ptr), intent(in) :: start
    type(c_ptr), intent(out) :: sweep
    character(len=*), intent(out), optional :: message
    jp_sweep_from = finish(jprom_sweep_from(model, opts, sweep_opts, start, c_null_funptr, c_null_ptr, sweep), message)
  end function

  integer function jp_sweep_free(sweep)
    use jprom_c, only: jprom_sweep_result_free
    type(c_ptr), intent(inout) :: sweep
    jp_sweep_free = int(jprom_sweep_result_free(sweep))
    sweep = c_null_ptr
  end function

  integer function jp_sweep_n_points(sweep, n)
    use jprom_c, only: jprom_sweep_result_n_points
    type(c_ptr), intent(in) :: sweep
    integer, intent(out) :: n
    integer(c_size_t) :: m
    jp_sweep_n_points = int(jprom_sweep_result_n_points(sweep, m))
    if (jp_sweep_n_points == JPROM_OK) n = int(m)
  end function

  !> Why the sweep ended (JPROM_SWEEP_REACHED_END, _STALLED, _POINT_CAP, _LEFT_BAND, _CANCELLED)
  !> and, unless it reached the end, where and why in words (truncated to len(why)).
  integer function jp_sweep_end(sweep, reason, why)
    use jprom_c, only: jprom_sweep_result_end_reason, jprom_sweep_result_failure_copy
    type(c_ptr), intent(in) :: sweep
    integer, intent(out) :: reason
    character(len=*), intent(out) :: why
    character(kind=c_char) :: buf(len(why) + 1)
    integer(c_size_t) :: written
    integer(c_int) :: r
    integer :: k
    why = ''
    jp_sweep_end = int(jprom_sweep_result_end_reason(sweep, r))
    if (jp_sweep_end /= JPROM_OK) return
    reason = int(r)
    ! a truncated copy is still a good prefix (the status then says JPROM_BAD_SIZE)
    k = int(jprom_sweep_result_failure_copy(sweep, buf, int(size(buf), c_size_t), written))
    do k = 1, min(len(why), int(written))
      why(k:k) = buf(k)
    end do
  end function

  !> A short name for an end reason ("reached_end", "stalled", ...; "unknown" otherwise).
  function jp_sweep_end_name(reason) result(name)
    use jprom_c, only: jprom_sweep_end_name
    integer, intent(in) :: reason
    character(len=:), allocatable :: name
    name = from_c(jprom_sweep_end_name(int(reason, c_int)))
  end function

  !> Whether the sweep covered the whole band.
  integer function jp_sweep_reached_end(sweep, reached)
    use jprom_c, only: jprom_sweep_result_reached_end
    type(c_ptr), intent(in) :: sweep
    logical, intent(out) :: reached
    integer(c_int) :: r
    jp_sweep_reached_end = int(jprom_sweep_result_reached_end(sweep, r))
    if (jp_sweep_reached_end == JPROM_OK) reached = r /= 0
  end function

  !> Number of folds and branch points located along the sweep, in the order the branch meets them.
  integer function jp_sweep_n_events(sweep, n)
    use jprom_c, only: jprom_sweep_result_n_events
    type(c_ptr), intent(in) :: sweep
    integer, intent(out) :: n
    integer(c_size_t) :: m
    jp_sweep_n_events = int(jprom_sweep_result_n_events(sweep, m))
    if (jp_sweep_n_events == JPROM_OK) n = int(m)
  end function

  !> Event i (1-based): kind (JPROM_EVENT_FOLD, JPROM_EVENT_BRANCH_POINT), angular frequency, the
  !> half-width it is located to, the point just before it (1-based) and the first output's
  !> first-harmonic amplitude there.
  integer function jp_sweep_event(sweep, i, kind, omega, omega_tolerance, after_point, amplitude)
    use jprom_c, only: jprom_sweep_result_event
    type(c_ptr), intent(in) :: sweep
    integer, intent(in) :: i
    integer, intent(out) :: kind, after_point
    real(c_double), intent(out) :: omega, omega_tolerance, amplitude
    integer(c_int) :: k
    integer(c_size_t) :: after
    jp_sweep_event = int(jprom_sweep_result_event(sweep, c_index(i), k, omega, omega_tolerance, after, amplitude))
    if (jp_sweep_event /= JPROM_OK) return
    kind = int(k)
    after_point = int(after) + 1
  end function

  !> A short name for an event kind ("fold", "branch_point"; "unknown" otherwise).
  function jp_event_kind_name(kind) result(name)
    use jprom_c, only: jprom_event_kind_name
    integer, intent(in) :: kind
    character(len=:), allocatable :: name
    name = from_c(jprom_event_kind_name(int(kind, c_int)))
  end function

  !> Number of parts of the band the sweep stepped over at fixed frequency (its gaps).
  integer function jp_sweep_n_gaps(sweep, n)
    use jprom_c, only: jprom_sweep_result_n_gaps
    type(c_ptr), intent(in) :: sweep
    integer, intent(out) :: n
    integer(c_size_t) :: m
    jp_sweep_n_gaps = int(jprom_sweep_result_n_gaps(sweep, m))
    if (jp_sweep_n_gaps == JPROM_OK) n = int(m)
  end function

  !> Gap i (1-based): the angular frequencies of the points before and after it, and why the
  !> continuation could not go on there (truncated to len(why)).
  integer function jp_sweep_gap(sweep, i, from, to, why)
    use jprom_c, only: jprom_sweep_result_gap, jprom_sweep_result_gap_reason_copy
    type(c_ptr), intent(in) :: sweep
    integer, intent(in) :: i
    real(c_double), intent(out) :: from, to
    character(len=*), intent(out) :: why
    character(kind=c_char) :: buf(len(why) + 1)
    integer(c_size_t) :: written
    integer :: k
    why = ''
    jp_sweep_gap = int(jprom_sweep_result_gap(sweep, c_index(i), from, to))
    if (jp_sweep_gap /= JPROM_OK) return
    ! a truncated copy is still a good prefix
    k = int(jprom_sweep_result_gap_reason_copy(sweep, c_index(i), buf, int(size(buf), c_size_t), written))
    do k = 1, min(len(why), int(written))
      why(k:k) = buf(k)
    end do
  end function

  !> Point i (1-based): angular frequency and first-harmonic amplitude at each output (1..size(amps)).
  integer function jp_sweep_point(sweep, i, omega, amps)
    use jprom_c, only: jprom_sweep_result_point_omega, jprom_sweep_result_point_amplitude
    type(c_ptr), intent(in) :: sweep
    integer, intent(in) :: i
    real(c_double), intent(out) :: omega, amps(:)
    integer :: j
    integer(c_int) :: s
    s = jprom_sweep_result_point_omega(sweep, c_index(i), omega)
    do j = 1, size(amps)
      if (s /= JPROM_OK) exit
      s = jprom_sweep_result_point_amplitude(sweep, c_index(i), 1_c_size_t, c_index(j), amps(j))
    end do
    jp_sweep_point = int(s)
  end function

  !> Point i (1-based): every harmonic coefficient at every output. coeffs(j, k + 1) is
  !> coefficient k (0 static, 2h-1 cos, 2h sin) at output j, so size(coeffs, 1) = n_outputs and
  !> size(coeffs, 2) = 2H + 1 (the C layout k * n_outputs + j read column-major, no copy).
  integer function jp_sweep_point_coeffs(sweep, i, coeffs, message)
    use jprom_c, only: jprom_sweep_result_point_output_coeffs
    type(c_ptr), intent(in) :: sweep
    integer, intent(in) :: i
    real(c_double), contiguous, intent(inout) :: coeffs(:, :)
    character(len=*), intent(inout) :: message
    jp_sweep_point_coeffs = finish(jprom_sweep_result_point_output_coeffs(sweep, c_index(i), coeffs, &
                                                                   int(size(coeffs), c_size_t)), message)
  end function

  !> Point i (1-based): energy dissipated per cycle by each contact, energy(1:n_contacts).
  integer function jp_sweep_point_energy(sweep, i, energy, message)
    use jprom_c, only: jprom_sweep_result_point_dissipated_energy
    type(c_ptr), intent(in) :: sweep
    integer, intent(in) :: i
    real(c_double), intent(inout) :: energy(:)
    character(len=*), intent(out), optional :: message
    real(c_double) :: buf(size(energy))
    integer(c_int) :: s
    s = jprom_sweep_result_point_dissipated_energy(sweep, c_index(i), buf, int(size(energy), c_size_t))
    if (s == JPROM_OK) energy = buf
    jp_sweep_point_energy = finish(s, message)
  end function

  !> Point i (1-based): Newton iterations and final relative residual.
  integer function jp_sweep_point_convergence(sweep, i, iterations, residual)
    use jprom_c, only: jprom_sweep_result_point_convergence
    type(c_ptr), intent(in) :: sweep
    integer, intent(in) :: i
    integer, intent(out) :: iterations
    real(c_double), intent(out) :: residual
    integer(c_size_t) :: it
    jp_sweep_point_convergence = int(jprom_sweep_result_point_convergence(sweep, c_index(i), it, residual))
    if (jp_sweep_point_convergence == JPROM_OK) iterations = int(it)
  end function

  !> Point i (1-based) copied out as a solution handle (contact states, save; free it).
  integer function jp_sweep_solution(sweep, i, solution, message)
    use jprom_c, only: jprom_sweep_result_point
    type(c_ptr), intent(in) :: sweep
    integer, intent(in) :: i
    type(c_ptr), intent(out) :: solution
    character(len=*), intent(out), optional :: message
    jp_sweep_solution = finish(jprom_sweep_result_point(sweep, c_index(i), solution), message)
  end function

  integer function jp_sweep_save(sweep, path, message)
    use jprom_c, only: jprom_sweep_result_save_json
    type(c_ptr), intent(in) :: sweep
    character(len=*), intent(in) :: path
    character(len=*), intent(out), optional :: message
    jp_sweep_save = finish(jprom_sweep_result_save_json(sweep, to_c(path)), message)
  end function

  integer function jp_sweep_load(path, sweep, message)
    use jprom_c, only: jprom_sweep_result_load_json
    character(len=*), intent(in) :: path
    type(c_ptr), intent(out) :: sweep
    character(len=*), intent(out), optional :: message
    jp_sweep_load = finish(jprom_sweep_result_load_json(to_c(path), sweep), message)
  end function

  ! ---- JP reduction ----

  !> JP basis predicted along the stuck mode for the band between omega_start and omega_end (rad/s, either order).
  integer function jp_basis_predict(model, opts, jp_opts, omega_start, omega_end, basis, message)
    use jprom_c, only: jprom_basis_predict_opts
    type(c_ptr), intent(in) :: model
    type(jprom_hbm_options), intent(in) :: opts
    type(jprom_jp_options), intent(in) :: jp_opts
    real(c_double), intent(in) :: omega_start, omega_end
    type(c_ptr), intent(out) :: basis
    character(len=*), intent(out), optional :: message
    jp_basis_predict = finish(jprom_basis_predict_opts(model, opts, jp_opts, omega_start, omega_end, basis), message)
  end function

  !> The JP basis of a full-order solution's own contact Jacobian.
  integer function jp_basis_from_solution(model, solution, opts, jp_opts, omega_start, omega_end, basis, message)
    use jprom_c, only: jprom_basis_from_solution
    type(c_ptr), intent(in) :: model, solution
    type(jprom_hbm_options), intent(in) :: opts
    type(jprom_jp_options), intent(in) :: jp_opts
    real(c_double), intent(in) :: omega_start, omega_end
    type(c_ptr), intent(out) :: basis
    character(len=*), intent(out), optional :: message
    jp_basis_from_solution = finish(jprom_basis_from_solution(model, solution, opts, jp_opts, omega_start, omega_end, basis), &
                                    message)
  end function

  !> Basis sizes: sizes(h) = n_h for h = 0..harmonics (sizes must hold H + 1 values).
  integer function jp_basis_sizes(basis, sizes, harmonics)
    use jprom_c, only: jprom_basis_sizes
    type(c_ptr), intent(in) :: basis
    integer, intent(out) :: sizes(0:), harmonics
    integer(c_size_t) :: buf(size(sizes)), hh
    jp_basis_sizes = int(jprom_basis_sizes(basis, buf, int(size(sizes), c_size_t), hh))
    if (jp_basis_sizes == JPROM_OK) then
      sizes = int(buf)
      harmonics = int(hh)
    end if
  end function

  integer function jp_basis_free(basis)
    use jprom_c, only: jprom_basis_free
    type(c_ptr), intent(inout) :: basis
    jp_basis_free = int(jprom_basis_free(basis))
    basis = c_null_ptr
  end function

  integer function jp_basis_save(basis, path, message)
    use jprom_c, only: jprom_basis_save_json
    type(c_ptr), intent(in) :: basis
    character(len=*), intent(in) :: path
    character(len=*), intent(out), optional :: message
    jp_basis_save = finish(jprom_basis_save_json(basis, to_c(path)), message)
  end function

  integer function jp_basis_load(path, basis, message)
    use jprom_c, only: jprom_basis_load_json
    character(len=*), intent(in) :: path
    type(c_ptr), intent(out) :: basis
    character(len=*), intent(out), optional :: message
    jp_basis_load = finish(jprom_basis_load_json(to_c(path), basis), message)
  end function

  !> Sweep of the reduced model (kind JPROM_ROM_FR or JPROM_ROM_NLR) on a given basis, with e*
  !> at every point.
  integer function jp_rom_sweep(model, basis, kind, opts, sweep_opts, sweep, message)
    use jprom_c, only: jprom_rom_sweep
    type(c_ptr), intent(in) :: model, basis
    integer, intent(in) :: kind
    type(jprom_hbm_options), intent(in) :: opts
    type(jprom_sweep_options), intent(in) :: sweep_opts
    type(c_ptr), intent(out) :: sweep
    character(len=*), intent(out), optional :: message
    jp_rom_sweep = finish(jprom_rom_sweep(model, basis, int(kind, c_int), opts, sweep_opts, c_null_funptr, c_null_ptr, &
                                          sweep), message)
  end function

  !> The self-correcting reduced sweep (kind JPROM_ROM_FR or JPROM_ROM_NLR): predicted basis,
  !> reduced sweep with e* at every point, basis corrected while the worst e*_1 exceeds
  !> jp_opts%threshold. Returns the sweep and the final basis (free both).
  integer function jp_rom_sweep_adaptive(model, kind, opts, sweep_opts, jp_opts, sweep, basis, message)
    use jprom_c, only: jprom_rom_sweep_adaptive
    type(c_ptr), intent(in) :: model
    integer, intent(in) :: kind
    type(jprom_hbm_options), intent(in) :: opts
    type(jprom_sweep_options), intent(in) :: sweep_opts
    type(jprom_jp_options), intent(in) :: jp_opts
    type(c_ptr), intent(out) :: sweep, basis
    character(len=*), intent(out), optional :: message
    jp_rom_sweep_adaptive = finish(jprom_rom_sweep_adaptive(model, int(kind, c_int), opts, sweep_opts, jp_opts, &
                                                            c_null_funptr, c_null_ptr, sweep, basis), message)
  end function

  !> Error predictor e*_h of point i (1-based) of a reduced sweep.
  integer function jp_sweep_point_error(sweep, i, h, e)
    use jprom_c, only: jprom_sweep_result_point_predicted_error
    type(c_ptr), intent(in) :: sweep
    integer, intent(in) :: i, h
    real(c_double), intent(out) :: e
    jp_sweep_point_error = int(jprom_sweep_result_point_predicted_error(sweep, c_index(i), int(h, c_size_t), e))
  end function

  integer function jp_sweep_n_corrections(sweep, n)
    use jprom_c, only: jprom_sweep_result_n_corrections
    type(c_ptr), intent(in) :: sweep
    integer, intent(out) :: n
    integer(c_size_t) :: m
    jp_sweep_n_corrections = int(jprom_sweep_result_n_corrections(sweep, m))
    if (jp_sweep_n_corrections == JPROM_OK) n = int(m)
  end function

  !> Correction k (1-based, in order) of a self-correcting sweep: its kind
  !> (JPROM_CORRECTION_REPLACED, _REGENERATED or _GAMMA_INCREASED), the omega it regenerated from or the
  !> new gamma, the worst e*_1 before and after it, and the basis sizes n_h after it, sizes(0:H).
  integer function jp_sweep_correction(sweep, k, kind, value, worst_before, worst_after, sizes, message)
    use jprom_c, only: jprom_sweep_result_correction
    type(c_ptr), intent(in) :: sweep
    integer, intent(in) :: k
    integer, intent(out) :: kind
    real(c_double), intent(out) :: value, worst_before, worst_after
    integer, intent(inout) :: sizes(0:)
    character(len=*), intent(out), optional :: message
    integer(c_size_t) :: buf(size(sizes))
    integer(c_int) :: s, kd
    s = jprom_sweep_result_correction(sweep, c_index(k), kd, value, worst_before, worst_after, buf, int(size(sizes), c_size_t))
    if (s == JPROM_OK) then
      kind = int(kd)
      sizes = int(buf)
    end if
    jp_sweep_correction = finish(s, message)
  end function

  !> Whether correction k (1-based) of a self-correcting sweep was swept over the band (.false.: judged without a
  !> pass, screened out at the points where the bases before it were poor; its worst_after is its error there).
  integer function jp_sweep_correction_swept(sweep, k, swept, message)
    use jprom_c, only: jprom_sweep_result_correction_swept
    type(c_ptr), intent(in) :: sweep
    integer, intent(in) :: k
    logical, intent(out) :: swept
    character(len=*), intent(out), optional :: message
    integer(c_int) :: s, v
    s = jprom_sweep_result_correction_swept(sweep, c_index(k), v)
    if (s == JPROM_OK) swept = v /= 0
    jp_sweep_correction_swept = finish(s, message)
  end function

  !> A short name for a correction kind ("replaced", "regenerated", "gamma_increased"; "unknown" otherwise).
  function jp_correction_kind_name(kind) result(name)
    use jprom_c, only: jprom_correction_kind_name
    integer, intent(in) :: kind
    character(len=:), allocatable :: name
    name = from_c(jprom_correction_kind_name(int(kind, c_int)))
  end function

  !> Why the corrections of a self-correcting sweep ended (JPROM_CORRECTIONS_WITHIN_THRESHOLD, _MAX_CORRECTIONS,
  !> _NO_PROGRESS or _CANCELLED) and the judged error of its final pass: above jp%threshold the basis stayed poor.
  !> JPROM_INVALID_VALUE for a sweep that is not a self-correcting sweep's result.
  integer function jp_sweep_correction_end(sweep, reason, judged_error, message)
    use jprom_c, only: jprom_sweep_result_correction_end
    type(c_ptr), intent(in) :: sweep
    integer, intent(out) :: reason
    real(c_double), intent(out) :: judged_error
    character(len=*), intent(out), optional :: message
    integer(c_int) :: s, e
    real(c_double) :: w
    s = jprom_sweep_result_correction_end(sweep, e, w)
    if (s == JPROM_OK) then
      reason = int(e)
      judged_error = w
    end if
    jp_sweep_correction_end = finish(s, message)
  end function

  !> The largest linearised error of the static contact displacement at the checks of a self-correcting
  !> sweep's final pass (+Infinity if not finite). Not judged by the corrections: above jp%threshold the static
  !> term X0 is poor while the first harmonic may be good (at gross slip; docs/formulation.md, 10.6).
  !> JPROM_INVALID_VALUE for any other sweep and for a sweep without checks.
  integer function jp_sweep_static_error(sweep, error, message)
    use jprom_c, only: jprom_sweep_result_static_error
    type(c_ptr), intent(in) :: sweep
    real(c_double), intent(out) :: error
    character(len=*), intent(out), optional :: message
    integer(c_int) :: s
    real(c_double) :: w
    s = jprom_sweep_result_static_error(sweep, w)
    if (s == JPROM_OK) error = w
    jp_sweep_static_error = finish(s, message)
  end function

  !> Whether a self-correcting sweep's result can be trusted (its final pass covered the band and every
  !> point's judged error is within jp%threshold) and, if not, why in words (truncated to len(why)). The peak of
  !> a sweep that is not trusted is not the reduced model's resonance. JPROM_INVALID_VALUE for any other sweep.
  integer function jp_sweep_trust(sweep, trusted, why, message)
    use jprom_c, only: jprom_sweep_result_trusted, jprom_sweep_result_trust_reason_copy
    type(c_ptr), intent(in) :: sweep
    logical, intent(out) :: trusted
    character(len=*), intent(out) :: why
    character(len=*), intent(out), optional :: message
    character(kind=c_char) :: buf(len(why) + 1)
    integer(c_size_t) :: written
    integer(c_int) :: s, t
    integer :: k
    why = ''
    s = jprom_sweep_result_trusted(sweep, t)
    if (s == JPROM_OK) then
      trusted = t /= 0
      ! a truncated copy is still a good prefix
      k = int(jprom_sweep_result_trust_reason_copy(sweep, buf, int(size(buf), c_size_t), written))
      do k = 1, min(len(why), int(written))
        why(k:k) = buf(k)
      end do
    end if
    jp_sweep_trust = finish(s, message)
  end function

  !> The judged error e_1 at point i (1-based) of a self-correcting sweep: the checked error where the point
  !> was checked against the full order, e*_1 elsewhere (+Infinity where no full-order solution was reached
  !> from it). Above jp%threshold the point is not good. JPROM_INVALID_VALUE for any other sweep or i out of range.
  integer function jp_sweep_judged_error(sweep, i, error, message)
    use jprom_c, only: jprom_sweep_result_point_judged_error
    type(c_ptr), intent(in) :: sweep
    integer, intent(in) :: i
    real(c_double), intent(out) :: error
    character(len=*), intent(out), optional :: message
    integer(c_int) :: s
    real(c_double) :: w
    s = jprom_sweep_result_point_judged_error(sweep, c_index(i), w)
    if (s == JPROM_OK) error = w
    jp_sweep_judged_error = finish(s, message)
  end function

  !> A short name for a correction end ("within_threshold", "max_corrections", "no_progress", "cancelled";
  !> "unknown" otherwise).
  function jp_correction_end_name(reason) result(name)
    use jprom_c, only: jprom_correction_end_name
    integer, intent(in) :: reason
    character(len=:), allocatable :: name
    name = from_c(jprom_correction_end_name(int(reason, c_int)))
  end function

  !> The actual error e_h, h = 0..H, of a reduced solution (a point of a reduced sweep on
  !> `basis`, from jp_sweep_solution) against a full-order solution at the same omega:
  !> e(0:H). model, basis, kind and opts are those of the reduced sweep.
  integer function jp_rom_actual_error(model, basis, kind, opts, rom_solution, full_solution, e, message)
    use jprom_c, only: jprom_rom_actual_error
    type(c_ptr), intent(in) :: model, basis, rom_solution, full_solution
    integer, intent(in) :: kind
    type(jprom_hbm_options), intent(in) :: opts
    real(c_double), intent(inout) :: e(0:)
    character(len=*), intent(out), optional :: message
    real(c_double) :: buf(size(e))
    integer(c_int) :: s
    s = jprom_rom_actual_error(model, basis, int(kind, c_int), opts, rom_solution, full_solution, buf, &
                               int(size(e), c_size_t))
    if (s == JPROM_OK) e = buf
    jp_rom_actual_error = finish(s, message)
  end function

  ! ---- FE models: node ids as the FE code numbers them; directions 1, 2, 3 = x, y, z ----

  !> FE model from sparse symmetric stiffness and mass (n x n, 1-BASED CSC as for
  !> jp_model_new_csc; nothing dense of size n is formed) and its nodes: node_ids(n_nodes) and
  !> node_rows(6, n_nodes), the 1-based matrix rows of each node's directions x, y, z, rx, ry,
  !> rz (0 for a direction the node does not have).
  integer function jp_fe_new_csc(n, stiffness_colptr, stiffness_rowind, stiffness_values, mass_colptr, mass_rowind, &
                                 mass_values, node_ids, node_rows, fe, message)
    use jprom_c, only: jprom_fe_model_new_csc
    integer, intent(in) :: n, stiffness_colptr(:), stiffness_rowind(:), mass_colptr(:), mass_rowind(:)
    real(c_double), intent(in) :: stiffness_values(:), mass_values(:)
    integer(c_int64_t), intent(in) :: node_ids(:), node_rows(:, :)
    type(c_ptr), intent(out) :: fe
    character(len=*), intent(out), optional :: message
    if (.not. (csc_fits(n, stiffness_colptr, stiffness_rowind, stiffness_values) .and. &
               csc_fits(n, mass_colptr, mass_rowind, mass_values))) then
      jp_fe_new_csc = refuse(JPROM_BAD_SIZE, 'jp_fe_new_csc: colptr must have n + 1 entries and rowind, values ' // &
                             'colptr(n + 1) - 1', message)
      return
    end if
    if (size(node_rows, 1) /= 6 .or. size(node_rows, 2) /= size(node_ids)) then
      jp_fe_new_csc = refuse(JPROM_BAD_SIZE, 'jp_fe_new_csc: node_rows must be (6, size(node_ids))', message)
      return
    end if
    ! 1-based rows to 0-based; 0 (no such direction) becomes the C API's -1
    jp_fe_new_csc = finish(jprom_fe_model_new_csc(int(n, c_size_t), c_index(stiffness_colptr), &
                                                  c_index(stiffness_rowind), stiffness_values, c_index(mass_colptr), &
                                                  c_index(mass_rowind), mass_values, int(size(node_ids), c_size_t), &
                                                  node_ids, node_rows - 1_c_int64_t, fe), message)
  end function

  !> FE model from a CalculiX *FREQUENCY, SOLVER=MATRIXSTORAGE job (path of its .inp deck).
  integer function jp_fe_load_calculix(inp, fe, message)
    use jprom_c, only: jprom_fe_model_load_calculix
    character(len=*), intent(in) :: inp
    type(c_ptr), intent(out) :: fe
    character(len=*), intent(out), optional :: message
    jp_fe_load_calculix = finish(jprom_fe_model_load_calculix(to_c(inp), fe), message)
  end function

  integer function jp_fe_free(fe)
    use jprom_c, only: jprom_fe_model_free
    type(c_ptr), intent(inout) :: fe
    jp_fe_free = int(jprom_fe_model_free(fe))
    fe = c_null_ptr
  end function

  !> Number of matrix rows (DoFs) of an FE model.
  integer function jp_fe_n_dof(fe, n)
    use jprom_c, only: jprom_fe_model_n_dof
    type(c_ptr), intent(in) :: fe
    integer, intent(out) :: n
    integer(c_size_t) :: m
    jp_fe_n_dof = int(jprom_fe_model_n_dof(fe, m))
    if (jp_fe_n_dof == JPROM_OK) n = int(m)
  end function

  !> The node ids of node set `name` into ids(1:n) (n = the set's size; ids must hold it).
  integer function jp_fe_node_set(fe, name, ids, n, message)
    use jprom_c, only: jprom_fe_model_node_set
    type(c_ptr), intent(in) :: fe
    character(len=*), intent(in) :: name
    integer(c_int64_t), intent(out) :: ids(:)
    integer, intent(out) :: n
    character(len=*), intent(out), optional :: message
    integer(c_size_t) :: count
    jp_fe_node_set = finish(jprom_fe_model_node_set(fe, to_c(name), ids, int(size(ids), c_size_t), count), message)
    n = int(count)
  end function

  !> Node-to-ground 3D friction contact on a node; frame(3, 3): rows t1, t2, n.
  integer function jp_fe_add_contact(fe, node, frame, kt1, kt2, kn, mu, n0, message)
    use jprom_c, only: jprom_fe_model_add_contact
    type(c_ptr), intent(in) :: fe
    integer(c_int64_t), intent(in) :: node
    real(c_double), intent(in) :: frame(3, 3), kt1, kt2, kn, mu, n0
    character(len=*), intent(out), optional :: message
    real(c_double) :: rows(9)
    rows = reshape(transpose(frame), [9])
    jp_fe_add_contact = finish(jprom_fe_model_add_contact(fe, node, rows, kt1, kt2, kn, mu, n0), message)
  end function

  !> Force f(3) on a node: harmonic 0 = static load, 1 = first harmonic (cos part).
  integer function jp_fe_add_force(fe, node, harmonic, f, message)
    use jprom_c, only: jprom_fe_model_add_force
    type(c_ptr), intent(in) :: fe
    integer(c_int64_t), intent(in) :: node
    integer, intent(in) :: harmonic
    real(c_double), intent(in) :: f(3)
    character(len=*), intent(out), optional :: message
    jp_fe_add_force = finish(jprom_fe_model_add_force(fe, node, int(harmonic, c_size_t), f), message)
  end function

  !> Output: direction 1, 2 or 3 (x, y, z) of a node; outputs are numbered in the order added.
  integer function jp_fe_add_output(fe, node, direction, message)
    use jprom_c, only: jprom_fe_model_add_output
    type(c_ptr), intent(in) :: fe
    integer(c_int64_t), intent(in) :: node
    integer, intent(in) :: direction
    character(len=*), intent(out), optional :: message
    jp_fe_add_output = finish(jprom_fe_model_add_output(fe, node, c_index(direction)), message)
  end function

  !> Keeps a node (all its DoFs) in the reduced model without a contact, load or output on it.
  integer function jp_fe_keep_node(fe, node, message)
    use jprom_c, only: jprom_fe_model_keep_node
    type(c_ptr), intent(in) :: fe
    integer(c_int64_t), intent(in) :: node
    character(len=*), intent(out), optional :: message
    jp_fe_keep_node = finish(jprom_fe_model_keep_node(fe, node), message)
  end function

  !> Craig-Bampton reduction (contact, loaded, output and kept nodes + cb_modes modes) to a model.
  integer function jp_fe_reduce(fe, cb_modes, model, message)
    use jprom_c, only: jprom_fe_model_reduce
    type(c_ptr), intent(in) :: fe
    integer, intent(in) :: cb_modes
    type(c_ptr), intent(out) :: model
    character(len=*), intent(out), optional :: message
    jp_fe_reduce = finish(jprom_fe_model_reduce(fe, int(cb_modes, c_size_t), model), message)
  end function

  !> The FE model without reduction (every FE DoF kept, dense M and K): JP on the FE model
  !> itself, the reference for jp_fe_reduce. For FE models up to a few thousand DoFs.
  integer function jp_fe_unreduced(fe, model, message)
    use jprom_c, only: jprom_fe_model_unreduced
    type(c_ptr), intent(in) :: fe
    type(c_ptr), intent(out) :: model
    character(len=*), intent(out), optional :: message
    jp_fe_unreduced = finish(jprom_fe_model_unreduced(fe, model), message)
  end function

  ! ---- damping forms and natural modes ----

  !> Viscous damping matrix added to the Rayleigh part (C = alpha M + beta K + c), c(n, n) with
  !> n the model's DoF count; replaces the reduced FE damping jp_fe_reduce put there.
  integer function jp_set_damping_matrix(model, c, message)
    use jprom_c, only: jprom_model_set_damping_matrix
    type(c_ptr), intent(in) :: model
    real(c_double), intent(in), target, contiguous :: c(:, :)
    character(len=*), intent(out), optional :: message
    if (size(c, 1) /= size(c, 2)) then
      jp_set_damping_matrix = refuse(JPROM_BAD_SIZE, 'jp_set_damping_matrix: c must be square', message)
      return
    end if
    jp_set_damping_matrix = finish(jprom_model_set_damping_matrix(model, c_loc(c), int(size(c, 1), c_size_t)), message)
  end function

  !> Modal damping: mode r (1-based, lowest first, of the model's K and M) gets ratios(r), every
  !> later mode others; replaces the added damping matrix.
  integer function jp_set_modal_damping_ratios(model, ratios, others, message)
    use jprom_c, only: jprom_model_set_modal_damping_ratios
    type(c_ptr), intent(in) :: model
    real(c_double), intent(in) :: ratios(:), others
    character(len=*), intent(out), optional :: message
    jp_set_modal_damping_ratios = finish(jprom_model_set_modal_damping_ratios(model, ratios, &
                                         int(size(ratios), c_size_t), others), message)
  end function

  !> Structural (hysteretic) damping: the harmonics see (1 + i eta) K.
  integer function jp_set_loss_factor(model, eta, message)
    use jprom_c, only: jprom_model_set_loss_factor
    type(c_ptr), intent(in) :: model
    real(c_double), intent(in) :: eta
    character(len=*), intent(out), optional :: message
    jp_set_loss_factor = finish(jprom_model_set_loss_factor(model, eta), message)
  end function

  !> The lowest size(frequency_hz) natural frequencies (Hz) of the model: stuck = .false. with the
  !> contacts open, .true. with their stuck springs; modal_force (same size) optional; n_modes
  !> optional: how many modes the model has.
  integer function jp_model_modes(model, stuck, frequency_hz, modal_force, n_modes, message)
    use jprom_c, only: jprom_model_modes
    type(c_ptr), intent(in) :: model
    logical, intent(in) :: stuck
    real(c_double), intent(out) :: frequency_hz(:)
    real(c_double), intent(out), target, optional :: modal_force(:)
    integer, intent(out), optional :: n_modes
    character(len=*), intent(out), optional :: message
    integer(c_size_t) :: count
    type(c_ptr) :: pf
    integer(c_int32_t) :: s
    pf = c_null_ptr
    if (present(modal_force)) then
      if (size(modal_force) /= size(frequency_hz)) then
        jp_model_modes = refuse(JPROM_BAD_SIZE, 'jp_model_modes: modal_force must have the size of frequency_hz', message)
        return
      end if
      pf = c_loc(modal_force)
    end if
    s = 0
    if (stuck) s = 1
    jp_model_modes = finish(jprom_model_modes(model, s, frequency_hz, pf, int(size(frequency_hz), c_size_t), count), &
                            message)
    if (present(n_modes)) n_modes = int(count)
  end function

  !> The FE model's viscous damping matrix C in CSC form (1-based, like jp_fe_new_csc), reduced
  !> with the model by jp_fe_reduce.
  integer function jp_fe_set_damping_csc(fe, n, colptr, rowind, values, message)
    use jprom_c, only: jprom_fe_model_set_damping_csc
    type(c_ptr), intent(in) :: fe
    integer, intent(in) :: n, colptr(:), rowind(:)
    real(c_double), intent(in) :: values(:)
    character(len=*), intent(out), optional :: message
    if (.not. csc_fits(n, colptr, rowind, values)) then
      jp_fe_set_damping_csc = refuse(JPROM_BAD_SIZE, 'jp_fe_set_damping_csc: colptr must have n + 1 entries and ' // &
                                     'rowind, values colptr(n + 1) - 1', message)
      return
    end if
    jp_fe_set_damping_csc = finish(jprom_fe_model_set_damping_csc(fe, int(n, c_size_t), c_index(colptr), &
                                   c_index(rowind), values), message)
  end function

  !> Fixes (clamps) direction (1..6: x, y, z, rx, ry, rz) of node: its row and column leave K, M, C.
  integer function jp_fe_fix_dof(fe, node, direction, message)
    use jprom_c, only: jprom_fe_model_fix_dof
    type(c_ptr), intent(in) :: fe
    integer(c_int64_t), intent(in) :: node
    integer, intent(in) :: direction
    character(len=*), intent(out), optional :: message
    jp_fe_fix_dof = finish(jprom_fe_model_fix_dof(fe, node, c_index(direction)), message)
  end function

  !> Craig-Bampton keeping the fixed-interface modes up to cutoff_hz, at most max_modes.
  integer function jp_fe_reduce_cutoff(fe, cutoff_hz, max_modes, model, message)
    use jprom_c, only: jprom_fe_model_reduce_cutoff
    type(c_ptr), intent(in) :: fe
    real(c_double), intent(in) :: cutoff_hz
    integer, intent(in) :: max_modes
    type(c_ptr), intent(out) :: model
    character(len=*), intent(out), optional :: message
    jp_fe_reduce_cutoff = finish(jprom_fe_model_reduce_cutoff(fe, cutoff_hz, int(max_modes, c_size_t), model), message)
  end function

  !> The lowest size(frequency_hz) natural frequencies (Hz) of the FE model on its supports.
  integer function jp_fe_modes(fe, frequency_hz, message)
    use jprom_c, only: jprom_fe_model_modes
    type(c_ptr), intent(in) :: fe
    real(c_double), intent(out) :: frequency_hz(:)
    character(len=*), intent(out), optional :: message
    jp_fe_modes = finish(jprom_fe_model_modes(fe, int(size(frequency_hz), c_size_t), frequency_hz), message)
  end function
end module jprom
