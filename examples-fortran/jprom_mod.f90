! Fortran 2008 interface to jprom's C API (include/jprom.h) through ISO_C_BINDING.
!
! Two layers:
!  * jprom_c: raw bind(C) interfaces, one per C function used here. Handles are type(c_ptr),
!    arrays are real(c_double), dimension(*) (column-major, as Fortran stores them), sizes and
!    indices are integer(c_size_t) and 0-BASED, exactly as in C.
!  * jprom (the module users `use`): thin Fortran-friendly wrappers. They return the status as
!    a default integer (0 = JPROM_OK), copy the error message into a character(len=*) on
!    failure, and take 1-BASED DoF / point / output indices, which they convert to 0-based.
module jprom_c
  use, intrinsic :: iso_c_binding
  implicit none
  integer(c_int), parameter :: JPROM_OK = 0
  integer(c_int), parameter :: JPROM_ROM_FR = 0, JPROM_ROM_NLR = 1
  !> Why a sweep ended (jprom_sweep_end in C).
  integer(c_int), parameter :: JPROM_SWEEP_REACHED_END = 0, JPROM_SWEEP_STALLED = 1, JPROM_SWEEP_POINT_CAP = 2, &
                               JPROM_SWEEP_LEFT_BAND = 3, JPROM_SWEEP_CANCELLED = 4

  type, bind(C) :: jprom_hbm_options
    integer(c_size_t) :: struct_size
    integer(c_size_t) :: harmonics
    integer(c_size_t) :: nt
    real(c_double) :: residual_tolerance
    integer(c_size_t) :: max_iterations
    integer(c_int) :: condensed
  end type

  type, bind(C) :: jprom_sweep_options
    integer(c_size_t) :: struct_size
    real(c_double) :: omega_start, omega_end
    real(c_double) :: initial_step, min_step, max_step
    integer(c_size_t) :: max_points
  end type

  type, bind(C) :: jprom_jp_options
    integer(c_size_t) :: struct_size
    real(c_double) :: gamma
    integer(c_size_t) :: n_samples, extra_outside
    integer(c_int) :: static_correction
    real(c_double) :: threshold
    integer(c_size_t) :: max_corrections
    real(c_double) :: gamma_growth, max_gamma
  end type

  interface
    integer(c_int) function jprom_model_new(n, mass, stiffness, out) bind(C, name="jprom_model_new")
      import :: c_int, c_size_t, c_double, c_ptr
      integer(c_size_t), value :: n
      real(c_double), dimension(*), intent(in) :: mass, stiffness
      type(c_ptr), intent(out) :: out
    end function
    integer(c_int) function jprom_model_free(model) bind(C, name="jprom_model_free")
      import :: c_int, c_ptr
      type(c_ptr), value :: model
    end function
    integer(c_int) function jprom_model_add_contact_3d(model, dofs_a, dofs_b, frame, kt1, kt2, kn, mu, n0) &
        bind(C, name="jprom_model_add_contact_3d")
      import :: c_int, c_size_t, c_double, c_ptr
      type(c_ptr), value :: model
      integer(c_size_t), dimension(*), intent(in) :: dofs_a
      type(c_ptr), value :: dofs_b
      real(c_double), dimension(*), intent(in) :: frame
      real(c_double), value :: kt1, kt2, kn, mu, n0
    end function
    integer(c_int) function jprom_model_set_rayleigh_damping(model, alpha, beta) &
        bind(C, name="jprom_model_set_rayleigh_damping")
      import :: c_int, c_double, c_ptr
      type(c_ptr), value :: model
      real(c_double), value :: alpha, beta
    end function
    integer(c_int) function jprom_model_set_harmonic_force(model, h, cos_part, sin_part, n) &
        bind(C, name="jprom_model_set_harmonic_force")
      import :: c_int, c_size_t, c_double, c_ptr
      type(c_ptr), value :: model
      integer(c_size_t), value :: h, n
      real(c_double), dimension(*), intent(in) :: cos_part, sin_part
    end function
    integer(c_int) function jprom_model_set_output_dofs(model, dofs, n) bind(C, name="jprom_model_set_output_dofs")
      import :: c_int, c_size_t, c_ptr
      type(c_ptr), value :: model
      integer(c_size_t), dimension(*), intent(in) :: dofs
      integer(c_size_t), value :: n
    end function
    integer(c_int) function jprom_hbm_options_default(out) bind(C, name="jprom_hbm_options_default")
      import :: c_int, jprom_hbm_options
      type(jprom_hbm_options), intent(out) :: out
    end function
    integer(c_int) function jprom_sweep_options_default(out) bind(C, name="jprom_sweep_options_default")
      import :: c_int, jprom_sweep_options
      type(jprom_sweep_options), intent(out) :: out
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
    integer(c_int) function jprom_sweep_free(sweep) bind(C, name="jprom_sweep_free")
      import :: c_int, c_ptr
      type(c_ptr), value :: sweep
    end function
    integer(c_int) function jprom_sweep_end_reason(sweep, out) bind(C, name="jprom_sweep_end_reason")
      import :: c_int, c_ptr
      type(c_ptr), value :: sweep
      integer(c_int), intent(out) :: out
    end function
    integer(c_int) function jprom_sweep_failure_copy(sweep, buf, len, written) bind(C, name="jprom_sweep_failure_copy")
      import :: c_int, c_size_t, c_ptr, c_char
      type(c_ptr), value :: sweep
      character(kind=c_char), dimension(*), intent(out) :: buf
      integer(c_size_t), value :: len
      integer(c_size_t), intent(out) :: written
    end function
    integer(c_int) function jprom_sweep_n_points(sweep, out) bind(C, name="jprom_sweep_n_points")
      import :: c_int, c_size_t, c_ptr
      type(c_ptr), value :: sweep
      integer(c_size_t), intent(out) :: out
    end function
    integer(c_int) function jprom_sweep_point_omega(sweep, i, out) bind(C, name="jprom_sweep_point_omega")
      import :: c_int, c_size_t, c_double, c_ptr
      type(c_ptr), value :: sweep
      integer(c_size_t), value :: i
      real(c_double), intent(out) :: out
    end function
    integer(c_int) function jprom_sweep_point_amplitude(sweep, i, h, j, out) bind(C, name="jprom_sweep_point_amplitude")
      import :: c_int, c_size_t, c_double, c_ptr
      type(c_ptr), value :: sweep
      integer(c_size_t), value :: i, h, j
      real(c_double), intent(out) :: out
    end function
    integer(c_int) function jprom_sweep_point_output_coeffs(sweep, i, buf, len) &
        bind(C, name="jprom_sweep_point_output_coeffs")
      import :: c_int, c_size_t, c_double, c_ptr
      type(c_ptr), value :: sweep
      integer(c_size_t), value :: i, len
      real(c_double), dimension(*), intent(out) :: buf
    end function
    integer(c_int) function jprom_jp_options_default(out) bind(C, name="jprom_jp_options_default")
      import :: c_int, jprom_jp_options
      type(jprom_jp_options), intent(out) :: out
    end function
    integer(c_int) function jprom_basis_predict_opts(model, opts, jp_opts, omega_lo, omega_hi, out) &
        bind(C, name="jprom_basis_predict_opts")
      import :: c_int, c_double, c_ptr, jprom_hbm_options, jprom_jp_options
      type(c_ptr), value :: model
      type(jprom_hbm_options), intent(in) :: opts
      type(jprom_jp_options), intent(in) :: jp_opts
      real(c_double), value :: omega_lo, omega_hi
      type(c_ptr), intent(out) :: out
    end function
    integer(c_int) function jprom_basis_sizes(basis, buf, len, harmonics) bind(C, name="jprom_basis_sizes")
      import :: c_int, c_size_t, c_ptr
      type(c_ptr), value :: basis
      integer(c_size_t), dimension(*), intent(out) :: buf
      integer(c_size_t), value :: len
      integer(c_size_t), intent(out) :: harmonics
    end function
    integer(c_int) function jprom_basis_free(basis) bind(C, name="jprom_basis_free")
      import :: c_int, c_ptr
      type(c_ptr), value :: basis
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
    integer(c_int) function jprom_sweep_n_corrections(sweep, out) bind(C, name="jprom_sweep_n_corrections")
      import :: c_int, c_size_t, c_ptr
      type(c_ptr), value :: sweep
      integer(c_size_t), intent(out) :: out
    end function
    integer(c_int) function jprom_sweep_point_predicted_error(sweep, i, h, out) &
        bind(C, name="jprom_sweep_point_predicted_error")
      import :: c_int, c_size_t, c_double, c_ptr
      type(c_ptr), value :: sweep
      integer(c_size_t), value :: i, h
      real(c_double), intent(out) :: out
    end function
    integer(c_int) function jprom_last_error_copy(buf, len, written) bind(C, name="jprom_last_error_copy")
      import :: c_int, c_size_t, c_char
      character(kind=c_char), dimension(*), intent(out) :: buf
      integer(c_size_t), value :: len
      integer(c_size_t), intent(out) :: written
    end function
    ! FE models (issue 13): from CalculiX output to a jprom model by Craig-Bampton
    integer(c_int) function jprom_fe_model_load_calculix(inp, fe) bind(C, name="jprom_fe_model_load_calculix")
      import :: c_int, c_char, c_ptr
      character(kind=c_char), dimension(*), intent(in) :: inp
      type(c_ptr), intent(out) :: fe
    end function
    integer(c_int) function jprom_fe_model_free(fe) bind(C, name="jprom_fe_model_free")
      import :: c_int, c_ptr
      type(c_ptr), value :: fe
    end function
    integer(c_int) function jprom_fe_model_node_set(fe, name, ids, len, count) bind(C, name="jprom_fe_model_node_set")
      import :: c_int, c_char, c_ptr, c_size_t, c_int64_t
      type(c_ptr), value :: fe
      character(kind=c_char), dimension(*), intent(in) :: name
      integer(c_int64_t), dimension(*), intent(out) :: ids
      integer(c_size_t), value :: len
      integer(c_size_t), intent(out) :: count
    end function
    integer(c_int) function jprom_fe_add_contact(fe, node, frame, kt1, kt2, kn, mu, n0) bind(C, name="jprom_fe_add_contact")
      import :: c_int, c_ptr, c_int64_t, c_double
      type(c_ptr), value :: fe
      integer(c_int64_t), value :: node
      real(c_double), dimension(*), intent(in) :: frame
      real(c_double), value :: kt1, kt2, kn, mu, n0
    end function
    integer(c_int) function jprom_fe_add_force(fe, node, harmonic, force) bind(C, name="jprom_fe_add_force")
      import :: c_int, c_ptr, c_int64_t, c_size_t, c_double
      type(c_ptr), value :: fe
      integer(c_int64_t), value :: node
      integer(c_size_t), value :: harmonic
      real(c_double), dimension(*), intent(in) :: force
    end function
    integer(c_int) function jprom_fe_add_output(fe, node, direction) bind(C, name="jprom_fe_add_output")
      import :: c_int, c_ptr, c_int64_t, c_size_t
      type(c_ptr), value :: fe
      integer(c_int64_t), value :: node
      integer(c_size_t), value :: direction
    end function
    integer(c_int) function jprom_fe_reduce(fe, cb_modes, model) bind(C, name="jprom_fe_reduce")
      import :: c_int, c_ptr, c_size_t
      type(c_ptr), value :: fe
      integer(c_size_t), value :: cb_modes
      type(c_ptr), intent(out) :: model
    end function
    integer(c_int) function jprom_model_set_dynamic_scale(model, scale) bind(C, name="jprom_model_set_dynamic_scale")
      import :: c_int, c_ptr, c_double
      type(c_ptr), value :: model
      real(c_double), value :: scale
    end function
  end interface
end module jprom_c

module jprom
  use, intrinsic :: iso_c_binding
  use jprom_c, only: jprom_hbm_options, jprom_sweep_options, jprom_jp_options, JPROM_OK, JPROM_ROM_FR, JPROM_ROM_NLR, &
                     JPROM_SWEEP_REACHED_END, JPROM_SWEEP_STALLED, JPROM_SWEEP_POINT_CAP, JPROM_SWEEP_LEFT_BAND, &
                     JPROM_SWEEP_CANCELLED
  implicit none
  private
  public :: jprom_hbm_options, jprom_sweep_options, jprom_jp_options, JPROM_OK, JPROM_ROM_FR, JPROM_ROM_NLR
  public :: JPROM_SWEEP_REACHED_END, JPROM_SWEEP_STALLED, JPROM_SWEEP_POINT_CAP, JPROM_SWEEP_LEFT_BAND, &
            JPROM_SWEEP_CANCELLED, jp_sweep_end
  public :: jp_model_new, jp_model_free, jp_add_ground_contact, jp_set_damping, jp_set_first_harmonic_force, &
            jp_set_outputs, jp_default_options, jp_sweep, jp_sweep_free, jp_sweep_n_points, jp_sweep_point, &
            jp_sweep_point_coeffs, jp_last_error
  public :: jp_fe_load_calculix, jp_fe_free, jp_fe_node_set, jp_fe_add_contact, jp_fe_add_force, jp_fe_add_output, &
            jp_fe_reduce, jp_set_dynamic_scale
  public :: jp_default_jp_options, jp_basis_predict, jp_basis_sizes, jp_basis_free, jp_rom_sweep_adaptive, &
            jp_sweep_n_corrections, jp_sweep_point_error

contains

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

  !> New model from n x n column-major mass and stiffness matrices.
  integer function jp_model_new(mass, stiffness, model, message)
    use jprom_c, only: jprom_model_new
    real(c_double), intent(in) :: mass(:, :), stiffness(:, :)
    type(c_ptr), intent(out) :: model
    character(len=*), intent(out), optional :: message
    jp_model_new = finish(jprom_model_new(int(size(mass, 1), c_size_t), mass, stiffness, model), message)
  end function

  integer function jp_model_free(model)
    use jprom_c, only: jprom_model_free
    type(c_ptr), intent(inout) :: model
    jp_model_free = int(jprom_model_free(model))
    model = c_null_ptr
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
    a = int(dofs - 1, c_size_t)
    rows = reshape(transpose(frame), [9])
    jp_add_ground_contact = finish(jprom_model_add_contact_3d(model, a, c_null_ptr, rows, kt1, kt2, kn, mu, n0), message)
  end function

  integer function jp_set_damping(model, alpha, beta, message)
    use jprom_c, only: jprom_model_set_rayleigh_damping
    type(c_ptr), intent(in) :: model
    real(c_double), intent(in) :: alpha, beta
    character(len=*), intent(out), optional :: message
    jp_set_damping = finish(jprom_model_set_rayleigh_damping(model, alpha, beta), message)
  end function

  integer function jp_set_first_harmonic_force(model, cos_part, sin_part, message)
    use jprom_c, only: jprom_model_set_harmonic_force
    type(c_ptr), intent(in) :: model
    real(c_double), intent(in) :: cos_part(:), sin_part(:)
    character(len=*), intent(out), optional :: message
    jp_set_first_harmonic_force = finish(jprom_model_set_harmonic_force(model, 1_c_size_t, cos_part, sin_part, &
        int(size(cos_part), c_size_t)), message)
  end function

  !> Output DoFs, 1-based.
  integer function jp_set_outputs(model, dofs, message)
    use jprom_c, only: jprom_model_set_output_dofs
    type(c_ptr), intent(in) :: model
    integer, intent(in) :: dofs(:)
    character(len=*), intent(out), optional :: message
    integer(c_size_t) :: d(size(dofs))
    d = int(dofs - 1, c_size_t)
    jp_set_outputs = finish(jprom_model_set_output_dofs(model, d, int(size(dofs), c_size_t)), message)
  end function

  subroutine jp_default_options(opts, sweep_opts)
    use jprom_c, only: jprom_hbm_options_default, jprom_sweep_options_default
    type(jprom_hbm_options), intent(out) :: opts
    type(jprom_sweep_options), intent(out) :: sweep_opts
    integer(c_int) :: s
    s = jprom_hbm_options_default(opts)
    s = jprom_sweep_options_default(sweep_opts)
  end subroutine

  !> Frequency sweep (no progress callback from this layer).
  integer function jp_sweep(model, opts, sweep_opts, sweep, message)
    use jprom_c, only: jprom_sweep
    type(c_ptr), intent(in) :: model
    type(jprom_hbm_options), intent(in) :: opts
    type(jprom_sweep_options), intent(in) :: sweep_opts
    type(c_ptr), intent(out) :: sweep
    character(len=*), intent(out), optional :: message
    jp_sweep = finish(jprom_sweep(model, opts, sweep_opts, c_null_funptr, c_null_ptr, sweep), message)
  end function

  integer function jp_sweep_free(sweep)
    use jprom_c, only: jprom_sweep_free
    type(c_ptr), intent(inout) :: sweep
    jp_sweep_free = int(jprom_sweep_free(sweep))
    sweep = c_null_ptr
  end function

  integer function jp_sweep_n_points(sweep, n)
    use jprom_c, only: jprom_sweep_n_points
    type(c_ptr), intent(in) :: sweep
    integer, intent(out) :: n
    integer(c_size_t) :: m
    jp_sweep_n_points = int(jprom_sweep_n_points(sweep, m))
    n = int(m)
  end function

  !> Why the sweep ended (JPROM_SWEEP_REACHED_END, _STALLED, _POINT_CAP, _LEFT_BAND, _CANCELLED)
  !> and, unless it reached the end, where and why in words (truncated to len(why)).
  integer function jp_sweep_end(sweep, reason, why)
    use jprom_c, only: jprom_sweep_end_reason, jprom_sweep_failure_copy
    type(c_ptr), intent(in) :: sweep
    integer, intent(out) :: reason
    character(len=*), intent(out) :: why
    character(kind=c_char) :: buf(len(why) + 1)
    integer(c_size_t) :: written
    integer(c_int) :: r
    integer :: k
    why = ''
    jp_sweep_end = int(jprom_sweep_end_reason(sweep, r))
    reason = int(r)
    if (jp_sweep_end /= JPROM_OK) return
    ! a truncated copy is still a good prefix (the status then says JPROM_BAD_SIZE)
    k = int(jprom_sweep_failure_copy(sweep, buf, int(size(buf), c_size_t), written))
    do k = 1, min(len(why), int(written))
      why(k:k) = buf(k)
    end do
  end function

  !> Point i (1-based): angular frequency and first-harmonic amplitude at each output (1..size(amps)).
  integer function jp_sweep_point(sweep, i, omega, amps)
    use jprom_c, only: jprom_sweep_point_omega, jprom_sweep_point_amplitude
    type(c_ptr), intent(in) :: sweep
    integer, intent(in) :: i
    real(c_double), intent(out) :: omega, amps(:)
    integer :: j
    integer(c_int) :: s
    s = jprom_sweep_point_omega(sweep, int(i - 1, c_size_t), omega)
    do j = 1, size(amps)
      if (s /= JPROM_OK) exit
      s = jprom_sweep_point_amplitude(sweep, int(i - 1, c_size_t), 1_c_size_t, int(j - 1, c_size_t), amps(j))
    end do
    jp_sweep_point = int(s)
  end function

  !> Point i (1-based): every harmonic coefficient at every output. coeffs(j, k + 1) is
  !> coefficient k (0 static, 2h-1 cos, 2h sin) at output j, so size(coeffs, 1) = n_outputs and
  !> size(coeffs, 2) = 2H + 1 (the C layout k * n_outputs + j read column-major, no copy).
  integer function jp_sweep_point_coeffs(sweep, i, coeffs, message)
    use jprom_c, only: jprom_sweep_point_output_coeffs
    type(c_ptr), intent(in) :: sweep
    integer, intent(in) :: i
    real(c_double), contiguous, intent(inout) :: coeffs(:, :)
    character(len=*), intent(inout) :: message
    jp_sweep_point_coeffs = finish(jprom_sweep_point_output_coeffs(sweep, int(i - 1, c_size_t), coeffs, &
                                                                   int(size(coeffs), c_size_t)), message)
  end function
  !> Defaults of the JP basis and self-correcting sweep settings (gamma 1e3, 100 samples,
  !> threshold 0.05 on e*_1, at most 5 corrections, ...).
  subroutine jp_default_jp_options(jp_opts)
    use jprom_c, only: jprom_jp_options_default
    type(jprom_jp_options), intent(out) :: jp_opts
    integer(c_int) :: s
    s = jprom_jp_options_default(jp_opts)
  end subroutine

  !> JP basis predicted along the stuck mode for the band [omega_lo, omega_hi] (rad/s).
  integer function jp_basis_predict(model, opts, jp_opts, omega_lo, omega_hi, basis, message)
    use jprom_c, only: jprom_basis_predict_opts
    type(c_ptr), intent(in) :: model
    type(jprom_hbm_options), intent(in) :: opts
    type(jprom_jp_options), intent(in) :: jp_opts
    real(c_double), intent(in) :: omega_lo, omega_hi
    type(c_ptr), intent(out) :: basis
    character(len=*), intent(out), optional :: message
    jp_basis_predict = finish(jprom_basis_predict_opts(model, opts, jp_opts, omega_lo, omega_hi, basis), message)
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

  integer function jp_sweep_n_corrections(sweep, n)
    use jprom_c, only: jprom_sweep_n_corrections
    type(c_ptr), intent(in) :: sweep
    integer, intent(out) :: n
    integer(c_size_t) :: m
    jp_sweep_n_corrections = int(jprom_sweep_n_corrections(sweep, m))
    n = int(m)
  end function

  !> Error predictor e*_h of point i (1-based) of a reduced sweep.
  integer function jp_sweep_point_error(sweep, i, h, e)
    use jprom_c, only: jprom_sweep_point_predicted_error
    type(c_ptr), intent(in) :: sweep
    integer, intent(in) :: i, h
    real(c_double), intent(out) :: e
    jp_sweep_point_error = int(jprom_sweep_point_predicted_error(sweep, int(i - 1, c_size_t), int(h, c_size_t), e))
  end function
  ! ---- FE models: node ids as the FE code numbers them; directions 1, 2, 3 = x, y, z ----

  !> FE model from a CalculiX *FREQUENCY, SOLVER=MATRIXSTORAGE job (path of its .inp deck).
  integer function jp_fe_load_calculix(inp, fe, message)
    use jprom_c, only: jprom_fe_model_load_calculix
    character(len=*), intent(in) :: inp
    type(c_ptr), intent(out) :: fe
    character(len=*), intent(out), optional :: message
    jp_fe_load_calculix = finish(jprom_fe_model_load_calculix(trim(inp) // c_null_char, fe), message)
  end function

  integer function jp_fe_free(fe)
    use jprom_c, only: jprom_fe_model_free
    type(c_ptr), intent(inout) :: fe
    jp_fe_free = int(jprom_fe_model_free(fe))
    fe = c_null_ptr
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
    jp_fe_node_set = finish(jprom_fe_model_node_set(fe, trim(name) // c_null_char, ids, int(size(ids), c_size_t), count), message)
    n = int(count)
  end function

  !> Node-to-ground 3D friction contact on a node; frame(3, 3): rows t1, t2, n.
  integer function jp_fe_add_contact(fe, node, frame, kt1, kt2, kn, mu, n0, message)
    use jprom_c, only: jprom_fe_add_contact
    type(c_ptr), intent(in) :: fe
    integer(c_int64_t), intent(in) :: node
    real(c_double), intent(in) :: frame(3, 3), kt1, kt2, kn, mu, n0
    character(len=*), intent(out), optional :: message
    real(c_double) :: rows(9)
    rows = reshape(transpose(frame), [9])
    jp_fe_add_contact = finish(jprom_fe_add_contact(fe, node, rows, kt1, kt2, kn, mu, n0), message)
  end function

  !> Force f(3) on a node: harmonic 0 = static load, 1 = first harmonic (cos part).
  integer function jp_fe_add_force(fe, node, harmonic, f, message)
    use jprom_c, only: jprom_fe_add_force
    type(c_ptr), intent(in) :: fe
    integer(c_int64_t), intent(in) :: node
    integer, intent(in) :: harmonic
    real(c_double), intent(in) :: f(3)
    character(len=*), intent(out), optional :: message
    jp_fe_add_force = finish(jprom_fe_add_force(fe, node, int(harmonic, c_size_t), f), message)
  end function

  !> Output: direction 1, 2 or 3 (x, y, z) of a node; outputs are numbered in the order added.
  integer function jp_fe_add_output(fe, node, direction, message)
    use jprom_c, only: jprom_fe_add_output
    type(c_ptr), intent(in) :: fe
    integer(c_int64_t), intent(in) :: node
    integer, intent(in) :: direction
    character(len=*), intent(out), optional :: message
    jp_fe_add_output = finish(jprom_fe_add_output(fe, node, int(direction - 1, c_size_t)), message)
  end function

  !> Craig-Bampton reduction (contact, loaded and output nodes + cb_modes modes) to a model.
  integer function jp_fe_reduce(fe, cb_modes, model, message)
    use jprom_c, only: jprom_fe_reduce
    type(c_ptr), intent(in) :: fe
    integer, intent(in) :: cb_modes
    type(c_ptr), intent(out) :: model
    character(len=*), intent(out), optional :: message
    jp_fe_reduce = finish(jprom_fe_reduce(fe, int(cb_modes, c_size_t), model), message)
  end function

  !> Scale of the harmonic excitation.
  integer function jp_set_dynamic_scale(model, scale, message)
    use jprom_c, only: jprom_model_set_dynamic_scale
    type(c_ptr), intent(in) :: model
    real(c_double), intent(in) :: scale
    character(len=*), intent(out), optional :: message
    jp_set_dynamic_scale = finish(jprom_model_set_dynamic_scale(model, scale), message)
  end function
end module jprom
